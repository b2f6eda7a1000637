//! The mutator and the fuzzing loop: mutants of a seed corpus, each run under
//! `catch_unwind`, a watchdog for hangs.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Values a hostile user writes in place of a number.
const NUMBERS: [&str; 18] = [
    "0",
    "-1",
    "1",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "1e12",
    "4294967296",
    "-0.0",
    "1e-308",
    "0.5",
    "1e9",
    "18446744073709551615",
    "2.0",
    "-1e-12",
    "3",
];

/// Spans of number literals in `text` (digits with sign, dot, exponent).
fn numbers(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = vec![];
    let mut i = 0;
    while i < text.len() {
        if text[i].is_ascii_digit() {
            let mut a = i;
            if a > 0 && (text[a - 1] == b'-' || text[a - 1] == b'+') {
                a -= 1;
            }
            let mut b = i;
            while b < text.len() && (text[b].is_ascii_digit() || matches!(text[b], b'.' | b'e' | b'E' | b'-' | b'+' | b'_')) {
                b += 1;
            }
            out.push((a, b));
            i = b;
        } else {
            i += 1;
        }
    }
    out
}

fn lines(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = vec![];
    let mut a = 0;
    for (i, &c) in text.iter().enumerate() {
        if c == b'\n' {
            out.push((a, i + 1));
            a = i + 1;
        }
    }
    if a < text.len() {
        out.push((a, text.len()));
    }
    out
}

/// One to four mutations of `seed` (`other`: a second seed to splice with).
pub fn mutate(rng: &mut ChaCha8Rng, seed: &[u8], other: &[u8]) -> Vec<u8> {
    let mut d = seed.to_vec();
    for _ in 0..rng.random_range(1..=4) {
        match rng.random_range(0..8) {
            0 | 1 | 2 => {
                let nums = numbers(&d);
                if !nums.is_empty() {
                    let (a, b) = nums[rng.random_range(0..nums.len())];
                    let v = NUMBERS[rng.random_range(0..NUMBERS.len())];
                    d.splice(a..b, v.bytes());
                }
            }
            3 => {
                let ls = lines(&d);
                if !ls.is_empty() {
                    let (a, b) = ls[rng.random_range(0..ls.len())];
                    d.drain(a..b);
                }
            }
            4 => {
                let ls = lines(&d);
                if !ls.is_empty() {
                    let (a, b) = ls[rng.random_range(0..ls.len())];
                    let copy = d[a..b].to_vec();
                    let at = lines(&d)[rng.random_range(0..ls.len())].0;
                    d.splice(at..at, copy);
                }
            }
            5 if !d.is_empty() => {
                let at = rng.random_range(0..d.len());
                d.truncate(at);
            }
            6 if !d.is_empty() => {
                let at = rng.random_range(0..d.len());
                d[at] ^= 1 << rng.random_range(0..8);
            }
            _ => {
                let ls = lines(other);
                if !ls.is_empty() {
                    let (a, b) = ls[rng.random_range(0..ls.len())];
                    let at = rng.random_range(0..=d.len());
                    d.splice(at..at, other[a..b].iter().copied());
                }
            }
        }
    }
    d
}

/// What a fuzzing run of one target did.
#[derive(Debug, Default)]
pub struct Report {
    pub executions: u64,
    pub failures: Vec<PathBuf>,
}

/// Runs `target` on mutants of the files in `corpus` for `seconds`, from `seed`; a
/// panic is saved in `failures` (the run goes on), an input running past `limit`
/// is saved and ends the process (exit 3).
pub fn fuzz(name: &str, target: fn(&[u8]), corpus: &Path, seconds: f64, seed: u64, limit: Duration, failures: &Path) -> Report {
    run(
        name,
        target,
        corpus,
        Bound::Time(Duration::from_secs_f64(seconds)),
        seed,
        limit,
        failures,
    )
}

/// [`fuzz`] for exactly `n` executions (deterministic: the tests' bound).
pub fn fuzz_n(name: &str, target: fn(&[u8]), corpus: &Path, n: u64, seed: u64, limit: Duration, failures: &Path) -> Report {
    run(name, target, corpus, Bound::Count(n), seed, limit, failures)
}

enum Bound {
    Time(Duration),
    Count(u64),
}

fn run(name: &str, target: fn(&[u8]), corpus: &Path, bound: Bound, seed: u64, limit: Duration, failures: &Path) -> Report {
    let mut seeds: Vec<Vec<u8>> = std::fs::read_dir(corpus)
        .map(|rd| rd.filter_map(|e| e.ok()).map(|e| e.path()).collect::<Vec<_>>())
        .unwrap_or_default()
        .into_iter()
        .filter_map(|p| std::fs::read(p).ok())
        .collect();
    seeds.sort();
    if seeds.is_empty() {
        seeds.push(vec![]);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut rep = Report::default();
    // the watchdog: the start of the current input (ms since `t0`, 0: none)
    let t0 = Instant::now();
    let started = Arc::new(AtomicU64::new(0));
    let current: Arc<std::sync::Mutex<Vec<u8>>> = Arc::default();
    {
        let (started, current, failures, name) = (started.clone(), current.clone(), failures.to_path_buf(), name.to_string());
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_millis(200));
            let s = started.load(Ordering::SeqCst);
            if s > 0 && t0.elapsed().as_millis() as u64 > s + limit.as_millis() as u64 {
                let input = current.lock().map(|c| c.clone()).unwrap_or_default();
                let path = save(&failures, &name, "hang", &input);
                eprintln!("fuzz {name}: an input ran past {limit:?}: saved in {}", path.display());
                std::process::exit(3);
            }
        });
    }
    let start = Instant::now();
    let more = |k: u64| match bound {
        Bound::Time(t) => start.elapsed() < t,
        Bound::Count(n) => k < n,
    };
    // seeds first, then mutants
    let mut k = 0usize;
    while more(k as u64) {
        let input = if k < seeds.len() {
            seeds[k].clone()
        } else {
            let a = &seeds[rng.random_range(0..seeds.len())];
            let b = &seeds[rng.random_range(0..seeds.len())];
            mutate(&mut rng, a, b)
        };
        k += 1;
        if let Ok(mut c) = current.lock() {
            c.clone_from(&input);
        }
        started.store(t0.elapsed().as_millis() as u64 + 1, Ordering::SeqCst);
        let r = std::panic::catch_unwind(AssertUnwindSafe(|| target(&input)));
        started.store(0, Ordering::SeqCst);
        rep.executions += 1;
        if r.is_err() {
            let path = save(failures, name, "panic", &input);
            eprintln!("fuzz {name}: a panic, input saved in {}", path.display());
            rep.failures.push(path);
        }
    }
    rep
}

fn save(dir: &Path, name: &str, what: &str, input: &[u8]) -> PathBuf {
    let _ = std::fs::create_dir_all(dir);
    let h = input
        .iter()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x100_0000_01b3));
    let p = dir.join(format!("{name}-{what}-{h:016x}"));
    let _ = std::fs::write(&p, input);
    p
}
