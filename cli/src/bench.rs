//! `nscdd bench`: the figures of docs/PERFORMANCE.md.
//!
//! - `nlgs` (2D), `nlgs3` (3D): NLGS throughput, contact updates per second on one
//!   thread, on a dense packing (a triangular lattice of touching disks in a box, a
//!   cubic lattice of touching spheres in a box of planes, under gravity, μ = 0.3,
//!   settled for 5 steps so that every contact carries load), timing plain sweeps
//!   of the solver's hot loop; one generic function for both dimensions.
//! - `deposit`: time per step of a deposit split by stage (detection, Delassus
//!   blocks, NLGS, update, output), from the example scene's settings.

use nscdd::registry::Registry;
use nscdd::solver::nlgs;
use nscdd::Error;
use std::time::Instant;

/// The settings both bench packings share: one step, the solver, one material and
/// its law (μ = 0.3).
const SETTINGS: &str = r#"[time]
step = 1e-3
steps = 1
[solver]
tolerance = 1e-4
max_sweeps = 200
[[materials]]
name = "g"
density = 1000.0
[[laws]]
materials = ["g", "g"]
friction = 0.3
"#;

/// The 2D bench packing: a triangular lattice of touching disks in a box of walls.
pub fn lattice(n: usize) -> String {
    let nx = (n as f64).sqrt().round().max(2.0) as usize;
    let ny = n.div_ceil(nx);
    let r = 0.01;
    let w = 2.0 * r * nx as f64 + r;
    format!(
        r#"
{SETTINGS}[[bodies]]
shape = "wall"
material = "g"
position = [{cx}, {fy}]
length = {wl}
thickness = {r}
fixed = true
[[bodies]]
shape = "wall"
material = "g"
position = [{lx}, {cy}]
rotation = 1.5707963267948966
length = {hl}
thickness = {r}
fixed = true
[[bodies]]
shape = "wall"
material = "g"
position = [{rx}, {cy}]
rotation = 1.5707963267948966
length = {hl}
thickness = {r}
fixed = true
[[generate]]
kind = "triangular_lattice"
material = "g"
nx = {nx}
ny = {ny}
radius = {r}
origin = [{r}, {r}]
"#,
        cx = w / 2.0,
        fy = -r / 2.0,
        wl = w + 4.0 * r,
        lx = -r / 2.0,
        rx = w + r / 2.0,
        cy = ny as f64 * r * 1.8 / 2.0,
        hl = ny as f64 * r * 1.8 + 4.0 * r,
    )
}

/// The 3D bench packing: a cubic lattice of touching spheres resting on a floor in
/// a box of planes.
pub fn lattice3(n: usize) -> String {
    let k = (n as f64).cbrt().ceil().max(2.0) as usize;
    let r = 0.01;
    let l = 2.0 * r * k as f64;
    let plane = |name: &str, pos: [f64; 3], rot: [f64; 3]| {
        format!(
            "[[bodies]]\nname = \"{name}\"\nshape = \"plane\"\nmaterial = \"g\"\nposition = {pos:?}\nrotation = {rot:?}\nfixed = true\n"
        )
    };
    let h = std::f64::consts::FRAC_PI_2;
    format!(
        r#"dimension = 3
{SETTINGS}{}{}{}{}{}
[[generate]]
kind = "sphere_lattice"
material = "g"
nx = {k}
ny = {k}
nz = {k}
radius = {r}
origin = [{r}, {r}, {r}]
"#,
        plane("floor", [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
        plane("x0", [0.0, 0.0, 0.0], [0.0, h, 0.0]),
        plane("x1", [l, 0.0, 0.0], [0.0, -h, 0.0]),
        plane("y0", [0.0, 0.0, 0.0], [-h, 0.0, 0.0]),
        plane("y1", [0.0, l, 0.0], [h, 0.0, 0.0]),
    )
}

/// NLGS contact updates per second on one thread, in either dimension: the scene
/// settles for 5 steps, then plain sweeps of the solver's hot loop over one more
/// step's contact set are timed.
pub fn nlgs<D: nscdd::scene::schema::SceneDim>(reg: &Registry, name: &str, scene: &str, sweeps: usize) -> Result<(), Error> {
    let mut s = nscdd::scene::Scene::<D>::load_str(scene, name, reg)?;
    let w = &mut s.world;
    for _ in 0..5 {
        w.step()?;
    }
    let c = &mut w.contacts;
    let mut order = vec![];
    nlgs::make_order(&mut order, c.len(), &w.solver, 0, D::N, |a| c.point3(a));
    let mut vel = w.bodies.vel.clone();
    let t = Instant::now();
    for _ in 0..sweeps {
        nlgs::sweep(c, &mut vel, &w.bodies.inv_mass, &order, 1.0, None);
    }
    let dt = t.elapsed().as_secs_f64();
    let updates = (c.len() * sweeps) as f64;
    println!(
        "{{\"bench\":\"{name}\",\"bodies\":{},\"contacts\":{},\"sweeps\":{},\"seconds\":{:.4},\"updates_per_second\":{:.4e},\"ns_per_update\":{:.2}}}",
        w.bodies.len(),
        c.len(),
        sweeps,
        dt,
        updates / dt,
        1e9 * dt / updates
    );
    Ok(())
}

/// An example scene's text (the benches run from the repository root).
fn example(name: &str) -> Result<String, Error> {
    let path = format!("examples/scenes/{name}");
    std::fs::read_to_string(&path).map_err(|e| Error::Io(format!("{path}: {e} (run the benches from the repository root)")))
}

/// Time per step of the deposit example, by stage.
pub fn deposit(reg: &Registry, n: usize, steps: usize) -> Result<(), Error> {
    let text = example("deposit.toml")?;
    let text = text.replace("count = 1000", &format!("count = {n}"));
    let mut s = nscdd::scene::load_str(&text, "deposit.toml", reg)?;
    let dir = std::env::temp_dir().join(format!("nscdd-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let mut vtk = (reg
        .writer::<nscdd::dim::D2>("vtk")
        .ok_or_else(|| Error::Io("no vtk writer registered".into()))?)();
    let every = s.output.every.max(1) as usize;
    let (mut det, mut del, mut sol, mut upd, mut out, mut sweeps, mut contacts) = (0.0, 0.0, 0.0, 0.0, 0.0, 0u64, 0usize);
    let t_all = Instant::now();
    for k in 1..=steps {
        let r = s.world.step()?;
        det += r.times.detect;
        del += r.times.delassus;
        sol += r.times.nlgs;
        upd += r.times.update;
        sweeps += r.solve.sweeps as u64;
        contacts = r.contacts;
        let t = Instant::now();
        if k % every == 0 {
            vtk.write(&s.world, &dir, k as u32)?;
            std::hint::black_box(nscdd::output::final_json(&s.world));
        }
        out += t.elapsed().as_secs_f64();
    }
    let total = t_all.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    let ms = |x: f64| 1e3 * x / steps as f64;
    println!(
        "{{\"bench\":\"deposit\",\"bodies\":{},\"steps\":{},\"final_contacts\":{},\"mean_sweeps\":{:.1},\"ms_per_step\":{{\"detection\":{:.4},\"delassus\":{:.4},\"nlgs\":{:.4},\"update\":{:.4},\"output\":{:.4},\"total\":{:.4}}}}}",
        s.world.bodies.len(),
        steps,
        contacts,
        sweeps as f64 / steps as f64,
        ms(det),
        ms(del),
        ms(sol),
        ms(upd),
        ms(out),
        ms(total)
    );
    Ok(())
}

/// The biaxial example for `n` disks: `examples/scenes/biaxial.toml` with its box,
/// walls and wall forces scaled by √(n / 2000) (the file unchanged for 2000).
fn biaxial_text(n: usize) -> Result<String, Error> {
    let text = example("biaxial.toml")?;
    let f = (n as f64 / 2000.0).sqrt();
    let subst = |t: String, from: &str, to: String| match t.contains(from) {
        true => Ok(t.replace(from, &to)),
        false => Err(Error::Io(format!("examples/scenes/biaxial.toml changed: `{from}` not found"))),
    };
    let mut t = subst(text, "count = 2000", format!("count = {n}"))?;
    if n != 2000 {
        let (w, h) = (0.4 * f, 0.535 * f);
        t = subst(t, "box = [0.0, 0.0, 0.4, 0.535]", format!("box = [0.0, 0.0, {w}, {h}]"))?;
        t = subst(t, "position = [0.2, -0.01]", format!("position = [{}, -0.01]", w / 2.0))?;
        t = subst(t, "position = [0.2, 0.55]", format!("position = [{}, {}]", w / 2.0, h + 0.015))?;
        t = subst(t, "position = [-0.01, 0.28]", format!("position = [-0.01, {}]", 0.28 * f))?;
        t = subst(t, "position = [0.41, 0.28]", format!("position = [{}, {}]", w + 0.01, 0.28 * f))?;
        t = subst(t, "length = 0.5", format!("length = {}", 0.5 * f))?;
        t = subst(t, "length = 0.6", format!("length = {}", 0.6 * f))?;
        t = subst(t, "-4000.0", format!("{:.3}", -4000.0 * f))?;
        t = subst(t, "-5200.0", format!("{:.3}", -5200.0 * f))?;
    }
    Ok(t)
}

/// The end of the biaxial example's compaction phase (s).
const COMPACTED: f64 = 0.3;

/// What `steps` NSCDD steps from the compacted biaxial sample did.
struct DdRun {
    stages: u64,
    sweeps: u64,
    unconverged: u64,
    interface_bodies: u64,
    contacts: u64,
    seconds: f64,
    solve_seconds: f64,
    vel_bits: Vec<[u64; 3]>,
}

/// Loads the biaxial scene, compacts it with the one-domain engine (t < 0.3 s, the
/// same steps for every call), then times `steps` NSCDD steps of the loading phase.
fn dd_run(reg: &Registry, text: &str, steps: usize, settings: nscdd::dd::DdSettings) -> Result<(DdRun, u64), Error> {
    let mut s = nscdd::scene::load_str(text, "biaxial.toml", reg)?;
    let w = &mut s.world;
    while w.t < COMPACTED - 0.5 * w.time.h {
        w.step()?;
    }
    let start = w.step;
    let mut n = nscdd::dd::Nscdd::new(settings);
    let mut r = DdRun {
        stages: 0,
        sweeps: 0,
        unconverged: 0,
        interface_bodies: 0,
        contacts: 0,
        seconds: 0.0,
        solve_seconds: 0.0,
        vel_bits: Vec::new(),
    };
    for _ in 0..steps {
        let t = Instant::now();
        let rep = n.step(w)?;
        r.seconds += t.elapsed().as_secs_f64();
        r.solve_seconds += rep.times.nlgs;
        r.stages += rep.stages as u64;
        r.sweeps += rep.solve.sweeps as u64;
        r.unconverged += !rep.solve.converged as u64;
        r.interface_bodies += rep.interface_bodies as u64;
        r.contacts += rep.contacts as u64;
    }
    r.vel_bits = w.bodies.vel.iter().map(|v| v.map(f64::to_bits)).collect();
    Ok((r, start))
}

/// NSCDD on the compacted biaxial sample: per decomposition, the stages (NSCDD
/// iterations) over `steps` loading steps relative to one subdomain, and with two
/// subdomains or more the wall time per step with 1 and 2 threads.
pub fn nscdd(reg: &Registry, n: usize, steps: usize, subdomains: &[(u32, u32)]) -> Result<(), Error> {
    let text = biaxial_text(n)?;
    let mut rows = Vec::new();
    let (mut s0, mut start, mut tol) = (None, 0, String::new());
    if let Ok(s) = nscdd::scene::load_str(&text, "biaxial.toml", reg) {
        let sv = &s.world.solver;
        tol = format!("{} {:e}, check every {}", sv.norm.name(), sv.tolerance, sv.check_every);
    }
    for &(nx, ny) in subdomains {
        let set = |threads| nscdd::dd::DdSettings {
            nx,
            ny,
            threads,
            ..Default::default()
        };
        let (one, st) = dd_run(reg, &text, steps, set(1))?;
        start = st;
        let stages0 = *s0.get_or_insert(one.stages);
        let per = |x: f64| 1e3 * x / steps as f64;
        let mut row = serde_json::json!({
            "nx": nx,
            "ny": ny,
            "subdomains": nx * ny,
            "stages": one.stages,
            "stages_rel": one.stages as f64 / stages0 as f64,
            "sweeps": one.sweeps,
            "unconverged_steps": one.unconverged,
            "mean_contacts": one.contacts as f64 / steps as f64,
            "mean_interface_bodies": one.interface_bodies as f64 / steps as f64,
            "ms_per_step_1": per(one.seconds),
            "solve_ms_per_step_1": per(one.solve_seconds),
        });
        if nx * ny >= 2 {
            let (two, _) = dd_run(reg, &text, steps, set(2))?;
            row["ms_per_step_2"] = per(two.seconds).into();
            row["solve_ms_per_step_2"] = per(two.solve_seconds).into();
            row["efficiency"] = (one.seconds / (2.0 * two.seconds)).into();
            row["solve_efficiency"] = (one.solve_seconds / (2.0 * two.solve_seconds)).into();
            row["identical"] = (one.vel_bits == two.vel_bits && one.stages == two.stages).into();
        }
        eprintln!("{row}");
        rows.push(row);
    }
    let out = serde_json::json!({
        "bench": "nscdd",
        "scene": "examples/scenes/biaxial.toml",
        "disks": n,
        "compacted_at_step": start,
        "steps": steps,
        "criterion": tol,
        "decompositions": rows,
    });
    println!("{out}");
    Ok(())
}
