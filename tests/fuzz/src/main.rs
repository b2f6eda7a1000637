//! `nscdd-fuzz [--seconds S] [--seed N] [TARGET…]`: runs the fuzz targets (all by
//! default) for S seconds each (default 60) on mutants of `tests/fuzz/corpus/TARGET/`;
//! exit 1 if any input panicked (saved under `target/fuzz-failures/`), 3 on a hang.

use std::path::Path;
use std::time::Duration;

fn main() {
    let mut seconds = 60.0;
    let mut seed = 1u64;
    let mut names = vec![];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seconds" => seconds = args.next().and_then(|v| v.parse().ok()).unwrap_or(seconds),
            "--seed" => seed = args.next().and_then(|v| v.parse().ok()).unwrap_or(seed),
            _ => names.push(a),
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let failures = root.join("../../target/fuzz-failures");
    // panics are reported by the fuzzer, with their input saved
    std::panic::set_hook(Box::new(|_| {}));
    let mut failed = false;
    for (name, target) in nscdd_fuzz::targets() {
        if !names.is_empty() && !names.iter().any(|n| n == name) {
            continue;
        }
        let corpus = root.join("corpus").join(name);
        let rep = nscdd_fuzz::mutate::fuzz(name, target, &corpus, seconds, seed, Duration::from_secs(20), &failures);
        println!(
            "{name}: {} executions in {seconds} s, {} panics",
            rep.executions,
            rep.failures.len()
        );
        failed |= !rep.failures.is_empty();
    }
    std::process::exit(if failed { 1 } else { 0 });
}
