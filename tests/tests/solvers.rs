//! The contact solvers of `[solver] method` (NLGS, Anderson-accelerated NLGS, the
//! semismooth Newton method on Alart–Curnier) on assembled problems:
//!
//! - each reaches a natural-map residual of 1e-8 on a generated 2D problem (the
//!   last step of a 300-disk deposit) and on the FCLIB files (3D), the residual it
//!   reports being the one recomputed from its r with the problem's own W and q;
//!   so do over-relaxed NLGS (ω = 1.2) and Anderson over over-relaxed sweeps
//!   (ω = 1.3), and the deposit steps with them, one domain and 2 × 2 subdomains;
//! - warm start: from a solution each stops at once, and from a loose solution in
//!   fewer iterations than from r = 0;
//! - a budget too small is reported as not converged, never silently;
//! - settings a method cannot use are refused naming the key (Newton's
//!   `solver.ordering` and `solver.relaxation`, Anderson's `scrambled` ordering,
//!   `solver.method` with bonds, Newton with NSCDD subdomains); Anderson honours
//!   the other orderings and the relaxation;
//! - Anderson over NSCDD's stages converges in fewer stages than NLGS, bitwise the
//!   same for any thread count.
//!
//! The physics tests run with each method, and over-relaxed, where it applies
//! (`physics::incline::every_method_gives_the_incline_answers`,
//! `physics::stacks::column_contact_forces_are_k_m_g`).

use nscdd::dd::{DdSettings, Nscdd};
use nscdd::fc::{problem_from_world, FcOptions, FcProblem};
use nscdd::solver::Method;

const METHODS: [Method; 3] = [Method::Nlgs, Method::Anderson, Method::Newton];

/// A ballistic deposit of 300 polydisperse disks on a floor, frictional.
fn deposit(extra_solver: &str) -> String {
    format!(
        r#"
[time]
step = 1e-3
steps = 100
[solver]
tolerance = 1e-4
max_sweeps = 20000
{extra_solver}
[[materials]]
name = "grain"
density = 2600.0
[[laws]]
materials = ["grain", "grain"]
friction = 0.4
[[bodies]]
name = "floor"
shape = "wall"
material = "grain"
position = [0.15, -0.01]
length = 0.5
thickness = 0.02
fixed = true
[[generate]]
kind = "disk_deposit"
material = "grain"
count = 300
radius_min = 0.008
radius_max = 0.012
box = [0.0, 0.0, 0.3, 1.0]
seed = 5
"#
    )
}

fn load(text: &str) -> Result<nscdd::scene::Scene, nscdd::error::InputError> {
    nscdd::scene::load_str(text, "solvers.toml", &nscdd_rigid_disks::registry())
}

/// The problem of the deposit's 150th step.
fn generated_problem() -> FcProblem {
    let mut s = load(&deposit("")).unwrap();
    for _ in 0..150 {
        s.world.step().unwrap();
    }
    let p = problem_from_world(&s.world);
    assert!(p.nc > 300, "only {} contacts", p.nc);
    p
}

fn opts(method: Method, tol: f64) -> FcOptions {
    FcOptions {
        max_sweeps: 200_000,
        check_every: 10,
        method,
        ..FcOptions::natural(tol)
    }
}

/// Solves `p` to 1e-8 with every method (and relaxation, [`RELAXED`]) and checks
/// the reported residual against the one recomputed from r. Returns each one's
/// iterations.
fn reach_1e8(label: &str, p: &FcProblem) -> Vec<u32> {
    RELAXED
        .iter()
        .map(|&(m, omega)| {
            let s = p.solve(&FcOptions {
                relaxation: omega,
                ..opts(m, 1e-8)
            });
            println!(
                "{label} {} ω = {omega}: {} iterations, residual {:.2e}",
                m.name(),
                s.sweeps,
                s.residual
            );
            assert!(s.converged && s.residual < 1e-8, "{label} {} ω = {omega}: {s:?}", m.name());
            let again = p.natural_residual(&s.r);
            assert!(again < 1e-8, "{label} {}: recomputed residual {again:.3e}", m.name());
            assert!(
                (again - s.residual).abs() <= 1e-6 * again + 1e-15,
                "{label} {}: {again} vs {}",
                m.name(),
                s.residual
            );
            s.sweeps
        })
        .collect()
}

#[test]
fn every_method_reaches_1e8_on_a_generated_problem() {
    let p = generated_problem();
    reach_1e8("deposit", &p);
}

#[test]
fn warm_start_and_budget() {
    let p = generated_problem();
    for m in METHODS {
        let exact = p.solve(&opts(m, 1e-9));
        assert!(exact.converged);
        // from its own solution a method stops at the first check
        let again = p.solve_from(Some(&exact.r), &opts(m, 1e-8));
        assert!(
            again.converged && again.sweeps <= 10,
            "{}: {} iterations from a solution",
            m.name(),
            again.sweeps
        );
        // from a loose solution it needs fewer iterations than from r = 0
        let loose = p.solve(&opts(Method::Nlgs, 1e-3));
        let cold = p.solve(&opts(m, 1e-8));
        let warm = p.solve_from(Some(&loose.r), &opts(m, 1e-8));
        assert!(
            warm.converged && warm.sweeps < cold.sweeps,
            "{}: warm {} vs cold {}",
            m.name(),
            warm.sweeps,
            cold.sweeps
        );
        // a budget too small is reported, with the residual reached
        let short = p.solve(&FcOptions {
            max_sweeps: 2,
            ..opts(m, 1e-12)
        });
        assert!(!short.converged && short.residual > 1e-12, "{}: {short:?}", m.name());
        let again = p.natural_residual(&short.r);
        assert!(
            (short.residual - again).abs() <= 1e-12 * again,
            "{}: {} vs {again}",
            m.name(),
            short.residual
        );
    }
}

/// Anderson stopped by its budget ends on its last iterate or its best sweep
/// output, whichever has the lower residual: never far worse than NLGS after as
/// many sweeps (a mixed iterate of a stagnating history alone could be).
#[test]
fn an_unconverged_anderson_solve_is_not_far_worse_than_nlgs() {
    let p = generated_problem();
    for budget in [3, 7, 15, 31, 63] {
        let o = |m| FcOptions {
            max_sweeps: budget,
            ..opts(m, 1e-14)
        };
        let (a, n) = (p.solve(&o(Method::Anderson)), p.solve(&o(Method::Nlgs)));
        println!("budget {budget}: anderson {:.3e}, nlgs {:.3e}", a.residual, n.residual);
        assert!(
            !a.converged && a.residual <= 1.5 * n.residual,
            "budget {budget}: {} vs {}",
            a.residual,
            n.residual
        );
    }
}

/// Every FCLIB file of `tests/data/fclib/` solved to 1e-8 by every method.
#[cfg(feature = "hdf5")]
#[test]
fn every_method_reaches_1e8_on_the_fclib_files() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/fclib");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "hdf5"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 4);
    for f in files {
        let p = nscdd::fc::read_any(&f).unwrap();
        reach_1e8(&f.file_name().unwrap().to_string_lossy(), &p);
    }
}

fn refused(extra_solver: &str, key: &str) {
    let text = deposit(extra_solver);
    let e = match load(&text) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("`{extra_solver}` loads"),
    };
    assert!(e.contains(key), "`{extra_solver}`: {e}");
}

/// The methods with a relaxation: each method unrelaxed, over-relaxed NLGS and
/// Anderson over over-relaxed sweeps.
const RELAXED: [(Method, f64); 5] = [
    (Method::Nlgs, 1.0),
    (Method::Anderson, 1.0),
    (Method::Newton, 1.0),
    (Method::Nlgs, 1.2),
    (Method::Anderson, 1.3),
];

#[test]
fn settings_a_method_cannot_use_are_refused() {
    refused("method = \"cholesky\"", "method");
    refused("method = \"newton\"\nordering = \"shuffled\"", "solver.ordering");
    refused("method = \"newton\"\nrelaxation = 0.8", "solver.relaxation");
    refused("relaxation = 2.0", "solver.relaxation");
    refused("relaxation = 0.0", "solver.relaxation");
    refused("method = \"anderson\"\nordering = \"scrambled\"", "solver.ordering");
    refused("method = \"newton\"\nordering = \"sorted\"", "solver.ordering");
    refused("sort_direction = [0.0, 1.0]", "solver.sort_direction");
    refused("ordering = \"sorted\"\nsort_direction = [0.0, 0.0]", "solver.sort_direction");
    refused("ordering = \"sorted\"\nsort_direction = [0.0, 1.0, 0.0]", "solver.sort_direction");
    refused("ordering = \"sorted\"\nsort_direction = [1e308, -inf]", "solver.sort_direction");
    // Newton has no place between NSCDD's gluing stages
    let text = deposit("method = \"newton\"").replace("[[materials]]", "[decomposition]\nnx = 2\nny = 1\n\n[[materials]]");
    let mut s = load(&text).unwrap();
    let dir = std::env::temp_dir().join(format!("nscdd_solvers_{}", std::process::id()));
    let e = nscdd::run::run(&mut s, &nscdd_rigid_disks::registry(), &dir, |_, _| {}).unwrap_err();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(e.to_string().contains("solver.method"), "{e}");
}

/// Anderson over NSCDD's stages (`nscdd::dd` module `anderson`): every step of
/// the deposit on 2 × 2 subdomains converges, in fewer stages than NLGS over the
/// same decomposition; 1 and 2 threads give bitwise the same result; the pile
/// settles as with NLGS.
#[test]
fn anderson_mixes_the_nscdd_stages() {
    let run = |method: &str, threads: usize| {
        let mut s = load(&deposit(&format!("method = \"{method}\""))).unwrap();
        let mut n = Nscdd::new(DdSettings {
            nx: 2,
            ny: 2,
            threads,
            ..Default::default()
        });
        let mut stages = 0;
        for k in 0..100 {
            let rep = n.step(&mut s.world).unwrap();
            assert!(rep.solve.converged, "{method}, {threads} thread(s), step {k}: {rep:?}");
            stages += rep.stages;
        }
        (s, stages)
    };
    let (nlgs, nlgs_stages) = run("nlgs", 1);
    let (one, stages) = run("anderson", 1);
    let (two, stages2) = run("anderson", 2);
    println!("stages over 100 steps: NLGS {nlgs_stages}, Anderson {stages}");
    assert!(stages < nlgs_stages, "Anderson {stages} stages, NLGS {nlgs_stages}");
    assert_eq!(stages, stages2);
    let bits = |s: &nscdd::scene::Scene| -> Vec<u64> {
        let w = &s.world;
        let v = w.bodies.vel.iter().flatten().chain(w.bodies.pos.iter().flatten());
        v.chain(w.contacts.r.iter().flatten()).map(|x| x.to_bits()).collect()
    };
    assert!(bits(&one) == bits(&two), "1 and 2 threads differ");
    let top = |s: &nscdd::scene::Scene| s.world.bodies.pos.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
    assert!((top(&one) - top(&nlgs)).abs() < 1e-3, "pile tops {} vs {}", top(&one), top(&nlgs));
}

/// Anderson mixes the world's sweeps in their visiting order and relaxation: the
/// deposit converges every step with each order and with ω = 0.8, and each order
/// gives its own (different) iterates.
#[test]
fn anderson_honours_ordering_and_relaxation() {
    let mut tops = vec![];
    for extra in ["", "ordering = \"reversed\"", "ordering = \"shuffled\"", "relaxation = 0.8"] {
        let mut s = load(&deposit(&format!("method = \"anderson\"\n{extra}"))).unwrap();
        for k in 0..100 {
            let rep = s.world.step().unwrap();
            assert!(rep.solve.converged, "`{extra}` step {k}: {rep:?}");
        }
        tops.push(s.world.bodies.pos.iter().map(|p| p[1]).fold(f64::MIN, f64::max));
    }
    assert!(tops[1] != tops[0] && tops[2] != tops[0], "the orders are used: {tops:?}");
    for t in &tops[1..] {
        assert!((t - tops[0]).abs() < 1e-3, "pile tops {tops:?}");
    }
}

/// A world stepped by each method: the one-domain stage reports LMGC90's norms and
/// convergence, and the deposit settles the same way (the methods solve the same
/// problems to the same tolerance, so the piles agree closely but not bitwise).
#[test]
fn every_method_steps_the_deposit() {
    let mut tops = vec![];
    for m in METHODS {
        let mut s = load(&deposit(&format!("method = \"{}\"", m.name()))).unwrap();
        for k in 0..100 {
            let rep = s.world.step().unwrap();
            assert!(rep.solve.converged, "{} step {k}: {rep:?}", m.name());
        }
        let top = s.world.bodies.pos.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
        tops.push(top);
    }
    for t in &tops[1..] {
        assert!((t - tops[0]).abs() < 1e-3, "pile tops {tops:?}");
    }
}

/// Over-relaxed sweeps step the deposit: every step converges, in one domain and
/// on 2 × 2 NSCDD subdomains, for NLGS at ω = 1.2 and Anderson at ω = 1.3, and
/// the pile settles as with plain NLGS.
#[test]
fn over_relaxed_sweeps_step_the_deposit() {
    let top = |s: &nscdd::scene::Scene| s.world.bodies.pos.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
    let mut plain = load(&deposit("")).unwrap();
    for _ in 0..100 {
        plain.world.step().unwrap();
    }
    for extra in ["relaxation = 1.2", "method = \"anderson\"\nrelaxation = 1.3"] {
        // one domain, then 2 × 2 subdomains
        for dd in [false, true] {
            let label = format!("`{extra}`{}", if dd { " on 2 × 2" } else { "" });
            let mut s = load(&deposit(extra)).unwrap();
            let mut n = dd.then(|| {
                Nscdd::new(DdSettings {
                    nx: 2,
                    ny: 2,
                    ..Default::default()
                })
            });
            for k in 0..100 {
                let solve = match n.as_mut() {
                    Some(n) => n.step(&mut s.world).unwrap().solve,
                    None => s.world.step().unwrap().solve,
                };
                assert!(solve.converged, "{label} step {k}: {solve:?}");
            }
            assert!((top(&s) - top(&plain)).abs() < 1e-3, "{label}: top {} vs {}", top(&s), top(&plain));
        }
    }
}

/// `ordering = "sorted"`: from the bottom up (against gravity) unless a direction is
/// given; the deposit settles as with storage order.
#[test]
fn sorted_goes_against_gravity_or_along_the_direction() {
    let up = load(&deposit("ordering = \"sorted\"")).unwrap();
    assert_eq!(up.world.solver.sort_direction.as_deref(), Some(&[0.0, 1.0][..]));
    let s = load(&deposit("ordering = \"sorted\"\nsort_direction = [3.0, 0.0]")).unwrap();
    assert_eq!(s.world.solver.sort_axis(2), [1.0, 0.0, 0.0], "a unit vector");
    for mut s in [up, s] {
        let mut last = None;
        for _ in 0..100 {
            last = Some(s.world.step().unwrap());
        }
        assert!(last.unwrap().solve.converged);
        let d = s.world.solver.sort_axis(2);
        let c = &s.world.contacts;
        let order = <nscdd::dd::Rigid2 as nscdd::dd::Family>::order(&s.world);
        let along: Vec<f64> = order
            .iter()
            .map(|&a| {
                let p = c.point3(a as usize);
                d[0] * p[0] + d[1] * p[1]
            })
            .collect();
        assert_eq!(along.len(), c.len());
        assert!(along.windows(2).all(|w| w[0] <= w[1]), "{d:?}: not sorted");
    }
}
