//! Every fuzz target on its seed corpus and on 3 000 mutants from a fixed seed
//! (deterministic; the long runs are `cargo run --release -p nscdd-fuzz`), and the
//! inputs that once panicked.

use std::path::Path;
use std::time::Duration;

#[test]
fn targets_survive_their_corpus_and_mutants() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let failures = std::env::temp_dir().join(format!("nscdd-fuzz-{}", std::process::id()));
    std::panic::set_hook(Box::new(|_| {}));
    for (name, target) in nscdd_fuzz::targets() {
        let corpus = root.join("corpus").join(name);
        assert!(corpus.read_dir().map(|d| d.count()).unwrap_or(0) > 0, "{name}: an empty corpus");
        // a time bound far above what 3 000 inputs take; executions are what is fixed
        let rep = nscdd_fuzz::mutate::fuzz_n(name, target, &corpus, 3000, 11, Duration::from_secs(60), &failures);
        assert!(rep.failures.is_empty(), "{name}: inputs panicked: {:?}", rep.failures);
        assert_eq!(rep.executions, 3000);
    }
    let _ = std::panic::take_hook();
    let _ = std::fs::remove_dir_all(&failures);
}

/// A 2D problem whose finite but extreme numbers overflow inside the local solver's
/// fallback: it used to panic in `f64::clamp` on a NaN bound (found by the fuzzer).
#[test]
fn overflowing_problem_does_not_panic() {
    let p = nscdd::fc::FcProblem {
        dim: 2,
        nc: 1,
        w: nscdd::fc::CooMatrix::from_triplets(
            2,
            &[
                (0, 0, 4.407212831701244e-280),
                (0, 1, 1.35807730653e-312),
                (1, 1, -3.105036184601506e231),
            ],
        ),
        q: vec![-3.105036184601461e231, 9.44e-322],
        mu: vec![0.0],
        meta: None,
    };
    assert!(p.validate().is_ok());
    let s = p.solve(&nscdd::fc::FcOptions {
        max_sweeps: 50,
        ..nscdd::fc::FcOptions::natural(1e-8)
    });
    // no panic, and an answer of the problem's size (not converged: it cannot be)
    assert_eq!(s.r.len(), 2);
    assert!(!s.converged || s.r.iter().all(|x| x.is_finite()));
}
