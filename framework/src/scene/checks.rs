//! The checks every scene file gets, whatever its dimension: materials, laws and
//! their detectors, time and solver settings, the alert distance, initial
//! overlaps, the decomposition and the pressure drives. Errors name the file, the
//! line and the key.

use super::*;
use crate::drive::BodyDrive;
use crate::world::BoxWalls;

/// Checks that every pair of materials that can touch (two bodies, one of them
/// movable) has a law, and makes the detector table of the kinds (`kinds[id]`: the
/// kind names) with `lookup` (the registry's 2D or 3D detectors). A pair of kinds
/// needs a detector when a law acts between their materials and one of them moves.
pub(crate) fn laws_and_detectors<T>(
    cx: &Ctx,
    bodies: &[BodyInfo],
    materials: &[Material],
    kinds: &[&'static str],
    laws: &[Option<std::sync::Arc<dyn crate::law::Law>>],
    declared: &[bool],
    lookup: impl Fn(&str, &str) -> Option<T>,
) -> Result<Vec<Option<T>>, InputError> {
    let (nm, nk) = (materials.len(), kinds.len());
    let mut first_mat = vec![None; nm];
    let mut mat_count = vec![0usize; nm];
    let mut mat_movable = vec![false; nm];
    let mut first_kind = vec![None; nk];
    let mut kind_movable = vec![false; nk];
    let mut kind_mats = vec![false; nk * nm];
    for bi in bodies {
        let (m, kd) = (bi.material, bi.kind);
        first_mat[m].get_or_insert(bi.origin);
        mat_count[m] += 1;
        first_kind[kd].get_or_insert(bi.origin);
        kind_mats[kd * nm + m] = true;
        mat_movable[m] |= bi.movable;
        kind_movable[kd] |= bi.movable;
    }
    for ma in 0..nm {
        for mb in ma..nm {
            if let (Some(oa), Some(_)) = (first_mat[ma], first_mat[mb]) {
                // a material touches itself only if two bodies are made of it
                let can_touch = ma != mb || mat_count[ma] >= 2;
                if can_touch && (mat_movable[ma] || mat_movable[mb]) && !declared[ma * nm + mb] {
                    let (x, y) = (&materials[ma].name, &materials[mb].name);
                    return Err(cx.err(
                        &origin_path(oa, "material"),
                        format!("no law for the material pair (`{x}`, `{y}`): add a [[laws]] entry with materials = [\"{x}\", \"{y}\"]"),
                    ));
                }
            }
        }
    }
    let mut table: Vec<Option<T>> = (0..nk * nk).map(|_| None).collect();
    for ka in 0..nk {
        for kb in 0..nk {
            let (na, nb) = (kinds[ka], kinds[kb]);
            let interact =
                (0..nm).any(|ma| (0..nm).any(|mb| kind_mats[ka * nm + ma] && kind_mats[kb * nm + mb] && laws[ma * nm + mb].is_some()));
            match lookup(na, nb) {
                Some(d) => table[ka * nk + kb] = Some(d),
                None if interact && (kind_movable[ka] || kind_movable[kb]) => {
                    let o = first_kind[ka].or(first_kind[kb]).unwrap_or(Origin::Body(0));
                    return Err(cx.err(
                        &origin_path(o, "shape"),
                        format!("no contact detector for the shape pair (`{na}`, `{nb}`) among the installed plugins"),
                    ));
                }
                None => {}
            }
        }
    }
    Ok(table)
}

/// The median of the finite positive shape sizes (None: there is none).
fn median_size(sizes: &[f64]) -> Option<f64> {
    let mut s: Vec<f64> = sizes.iter().copied().filter(|x| x.is_finite() && *x > 0.0).collect();
    s.sort_by(|a, c| a.total_cmp(c));
    s.get(s.len() / 2).copied()
}

/// The alert distance: `detection.alert`, or 0.1 × the median shape size.
pub(crate) fn alert_distance(cx: &Ctx, d: &schema::DetectionSpec, sizes: &[f64]) -> Result<f64, InputError> {
    match d.alert {
        Some(a) if !(a >= 0.0 && a.is_finite()) => Err(cx.err(&[k("detection"), k("alert")], format!("must be ≥ 0, got {a}"))),
        Some(a) => Ok(a),
        None => Ok(0.1 * median_size(sizes).unwrap_or(1.0)),
    }
}

/// Refuses an alert distance that makes every step detect and solve a number of
/// contact candidates no packing has: with the movable bodies' centres `pts` (z = 0
/// in 2D, `dim` coordinates used) spread evenly over their bounding box, a body sees
/// the others within alert + the median size; more than max(2·10⁴, 64 N) pairs over
/// the sample (a packing has fewer than 6 per body) is an input error naming
/// `detection.alert` (an alert of 10⁸ m on 2000 disks made 2·10⁶ contacts per step,
/// a run of minutes per step).
pub(crate) fn check_alert_work(
    cx: &Ctx,
    alert: f64,
    pts: impl Iterator<Item = [f64; 3]>,
    sizes: &[f64],
    dim: usize,
) -> Result<(), InputError> {
    // (one pass over the centres: their number and bounding box)
    let (mut n, mut lo, mut hi) = (0.0, [f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in pts {
        n += 1.0;
        for d in 0..3 {
            (lo[d], hi[d]) = (lo[d].min(p[d]), hi[d].max(p[d]));
        }
    }
    if n < 2.0 {
        return Ok(());
    }
    let size = median_size(sizes).unwrap_or(0.0);
    let reach = 2.0 * (alert + size);
    let mut share = 1.0;
    for d in 0..dim {
        let extent = (hi[d] - lo[d]).max(size);
        if extent > 0.0 && extent.is_finite() {
            share *= (reach / extent).min(1.0);
        }
    }
    let per_body = ((n - 1.0) * share).min(n - 1.0);
    let pairs = 0.5 * n * per_body;
    if pairs <= (64.0 * n).max(2e4) {
        return Ok(());
    }
    Err(cx.err(
        &[k("detection"), k("alert")],
        format!(
            "{alert} makes about {pairs:.1e} contact candidates ({per_body:.0} per body; a packing has fewer than 12), each step would detect and solve them all: use a fraction of the bodies' size (the default is 0.1 × the median size, {:.3e})",
            0.1 * size
        ),
    ))
}

/// Initial interpenetrations beyond `detection.overlap_tolerance` × the smaller
/// shape size, among the detected `(i, j, gap)` of materials that interact.
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_overlaps<'n>(
    cx: &Ctx,
    d: &schema::DetectionSpec,
    contacts: impl Iterator<Item = (usize, usize, f64)>,
    sizes: &[f64],
    laws: &[Option<std::sync::Arc<dyn crate::law::Law>>],
    nm: usize,
    material: impl Fn(usize) -> usize,
    name: &dyn Fn(usize) -> Option<&'n str>,
    origins: &[Origin],
) -> Result<(), InputError> {
    let tol = d.overlap_tolerance;
    if !(tol >= 0.0) {
        return Err(cx.err(&[k("detection"), k("overlap_tolerance")], "must be ≥ 0"));
    }
    for (i, j, gap) in contacts {
        if laws[material(i) * nm + material(j)].is_none() {
            continue; // materials declared never to interact
        }
        let lim = tol * sizes[i].min(sizes[j]);
        if gap < -lim {
            let label = |x: usize| match name(x) {
                Some(n) => format!("{x} (`{n}`)"),
                None => format!("{x}"),
            };
            return Err(cx.err(
                &origin_path(origins[i], "position"),
                format!(
                    "bodies {} and {} overlap by {:.3e} m, more than the tolerance {:.3e} m (detection.overlap_tolerance × the smaller size)",
                    label(i),
                    label(j),
                    -gap,
                    lim
                ),
            ));
        }
    }
    Ok(())
}

/// A scheme name (`decentralized` or `centralized`).
pub fn parse_scheme(name: &str) -> Result<crate::dd::Scheme, String> {
    match name {
        "decentralized" => Ok(crate::dd::Scheme::Decentralized),
        "centralized" => Ok(crate::dd::Scheme::Centralized),
        other => Err(format!("unknown scheme `{other}`; expected `decentralized` or `centralized`")),
    }
}

pub(crate) fn decomposition(cx: &Ctx, d: &schema::DecompositionSpec, movable: usize) -> Result<crate::dd::DdConfig, InputError> {
    if d.by_model == Some(true) && !cx.families {
        return Err(cx.err(
            &[k("decomposition"), k("by_model")],
            "subdomains by model need a body family beside the rigid bodies (a plugin's section, e.g. deformable bodies)",
        ));
    }
    let p = |key: &str| vec![k("decomposition"), k(key)];
    let int = |key: &str, v: Option<i64>, min: i64, def: i64| -> Result<i64, InputError> {
        let v = v.unwrap_or(def);
        if v < min || v > u32::MAX as i64 {
            return Err(cx.err(&p(key), format!("must be an integer ≥ {min}, got {v}")));
        }
        Ok(v)
    };
    let def = crate::dd::DdSettings::default();
    let mut c = crate::dd::DdConfig::default();
    c.by_model = d.by_model == Some(true);
    c.dd.nx = int("nx", d.nx, 1, def.nx as i64)? as u32;
    c.dd.ny = int("ny", d.ny, 1, def.ny as i64)? as u32;
    c.dd.nz = int("nz", d.nz, 1, 1)? as u32;
    c.dd.sweeps_per_gluing = int("sweeps_per_gluing", d.sweeps_per_gluing, 1, 1)? as u32;
    c.dd.threads = int("threads", d.threads, 1, 1)? as usize;
    c.repartition_every = int("repartition_every", d.repartition_every, 1, 1)? as u32;
    if let Some(f) = d.rebalance {
        if !(f.is_finite() && f > 1.0) {
            return Err(cx.err(
                &p("rebalance"),
                format!("the growth of the load imbalance that triggers a repartition must be a number > 1, got {f}"),
            ));
        }
        if c.repartition_every == 1 {
            let m = "the subdomains are re-partitioned at every step already (repartition_every = 1): set repartition_every > 1, or remove rebalance";
            return Err(cx.err(&p("rebalance"), m));
        }
        c.rebalance = Some(f);
    }
    c.balanced_grid = match d.grid.as_deref() {
        None | Some("uniform") => false,
        Some("balanced") => true,
        Some(g) => return Err(cx.err(&p("grid"), format!("`uniform` or `balanced` expected, got `{g}`"))),
    };
    if let Some(s) = &d.scheme {
        c.dd.scheme = parse_scheme(s).map_err(|m| cx.err(&p("scheme"), m))?;
    }
    // a family's body (a deformable one) may be copied into any number of subdomains: no bound then
    let movable = if cx.families { usize::MAX } else { movable };
    c.check_capacity(movable).map_err(|(key, m)| {
        // name a key the section has
        let key = match (d.nx.is_some(), d.ny.is_some(), d.nz.is_some()) {
            (true, _, _) | (false, false, false) => key,
            (false, true, _) => "ny",
            (false, false, true) => "nz",
        };
        cx.err(&p(key), m)
    })?;
    Ok(c)
}

/// The most steps a scene may ask for (10¹²: eleven days at a microsecond a step).
const MAX_STEPS: f64 = 1e12;

pub(crate) fn time_settings<B>(cx: &Ctx, sf: &SceneFile<B>) -> Result<TimeSettings, InputError> {
    let t = &sf.time;
    if !(t.step > 0.0 && t.step.is_finite()) {
        return Err(cx.err(
            &[k("time"), k("step")],
            format!("the step must be a positive number of seconds, got {}", t.step),
        ));
    }
    if !(0.5..=1.0).contains(&t.theta) {
        return Err(cx.err(&[k("time"), k("theta")], format!("θ must lie in [0.5, 1], got {}", t.theta)));
    }
    let steps = match (t.steps, t.duration) {
        (Some(n), None) => n as f64,
        (None, Some(d)) if d >= 0.0 && d.is_finite() => {
            let n = (d / t.step).round();
            if d > 0.0 && n < 1.0 {
                let msg = format!(
                    "{d} s is less than half a step (time.step = {:e} s): the scene would run no step",
                    t.step
                );
                return Err(cx.err(&[k("time"), k("duration")], msg));
            }
            n
        }
        (None, Some(d)) => return Err(cx.err(&[k("time"), k("duration")], format!("must be ≥ 0, got {d}"))),
        _ => return Err(cx.err(&[k("time")], "give exactly one of `steps` or `duration`")),
    };
    if steps > MAX_STEPS {
        let key = if t.steps.is_some() { "steps" } else { "duration" };
        let msg = format!("{steps:e} steps: more than a run can take (at most {MAX_STEPS:e}); lengthen time.step or shorten the run");
        return Err(cx.err(&[k("time"), k(key)], msg));
    }
    let steps = steps as u64;
    Ok(TimeSettings {
        h: t.step,
        theta: t.theta,
        steps,
    })
}

/// The scene's `[solver]`, checked, with `sort_direction` resolved (a scene of
/// gravity `gravity`).
pub(crate) fn solver_settings(
    cx: &Ctx,
    s: &crate::solver::SolverSettings,
    gravity: &[f64],
) -> Result<crate::solver::SolverSettings, InputError> {
    validate_solver(cx, s)?;
    let mut s = s.clone();
    sort_direction(cx, &mut s, gravity)?;
    Ok(s)
}

fn validate_solver(cx: &Ctx, s: &crate::solver::SolverSettings) -> Result<(), InputError> {
    let p = |key: &str| vec![k("solver"), k(key)];
    // below 1e-15 the norms (relative to the impulses' scale) are under the round-off
    // of double precision: no solve reaches it, every step runs to max_sweeps
    if !(s.tolerance >= 1e-15 && s.tolerance.is_finite()) {
        return Err(cx.err(
            &p("tolerance"),
            format!(
                "must be ≥ 1e-15 (double precision reaches no less) and finite, got {:e}",
                s.tolerance
            ),
        ));
    }
    if s.max_sweeps == 0 {
        return Err(cx.err(&p("max_sweeps"), "must be ≥ 1"));
    }
    if s.check_every == 0 {
        return Err(cx.err(&p("check_every"), "must be ≥ 1"));
    }
    if !(s.relaxation > 0.0 && s.relaxation < 2.0) {
        return Err(cx.err(&p("relaxation"), format!("ω must lie in (0, 2), got {}", s.relaxation)));
    }
    // Newton sweeps nothing (its fallback sweeps the assembled W in storage order,
    // unrelaxed); Anderson mixes the world's sweeps in their order and relaxation,
    // but one map a step (no re-permutation between blocks)
    let m = s.method.name();
    if s.method == crate::solver::Method::Newton {
        if s.ordering != crate::solver::Ordering::Stored {
            let msg =
                format!("`{m}` visits the contacts in storage order; `ordering` is an NLGS setting (remove it or use method = \"nlgs\")");
            return Err(cx.err(&p("ordering"), msg));
        }
        if s.relaxation != 1.0 {
            let msg = format!("`{m}` takes unrelaxed sweeps; `relaxation` is an NLGS setting (remove it or use method = \"nlgs\")");
            return Err(cx.err(&p("relaxation"), msg));
        }
    }
    if s.method == crate::solver::Method::Anderson && s.ordering == crate::solver::Ordering::Scrambled {
        let msg = format!(
            "`{m}` mixes the iterates of one sweep map a step; `scrambled` re-permutes the contacts between blocks \
             (use \"stored\", \"reversed\" or \"shuffled\", or method = \"nlgs\")"
        );
        return Err(cx.err(&p("ordering"), msg));
    }
    Ok(())
}

/// `[solver] sort_direction`: read by `ordering = "sorted"` alone, D finite numbers
/// not all zero, kept as a unit vector; for `sorted` without it, against gravity
/// (from the bottom up), or (left unset) along the last axis, y in 2D and z in 3D,
/// in a scene without gravity.
fn sort_direction(cx: &Ctx, s: &mut crate::solver::SolverSettings, gravity: &[f64]) -> Result<(), InputError> {
    let key = [k("solver"), k("sort_direction")];
    let n = gravity.len();
    let sorted = s.ordering == crate::solver::Ordering::Sorted;
    let given = s.sort_direction.take();
    if given.is_some() && !sorted {
        let msg = "`sort_direction` is the direction of ordering = \"sorted\" only (remove it or set ordering = \"sorted\")";
        return Err(cx.err(&key, msg));
    }
    let bad = || {
        cx.err(
            &key,
            format!("must be {n} finite numbers, not all zero (a direction of the scene's {n}D space)"),
        )
    };
    let d = match given {
        Some(d) if d.len() != n => return Err(bad()),
        Some(d) => d,
        None if sorted && gravity.iter().any(|&g| g != 0.0) => gravity.iter().map(|g| -g).collect(),
        None => return Ok(()),
    };
    // scaled by its largest component first: no overflow or underflow on the way
    let big = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(big.is_finite() && big > 0.0) {
        return Err(bad());
    }
    let norm = d.iter().map(|x| (x / big) * (x / big)).sum::<f64>().sqrt();
    s.sort_direction = Some(d.iter().map(|x| x / big / norm + 0.0).collect());
    Ok(())
}

pub(crate) fn materials<B>(cx: &Ctx, sf: &SceneFile<B>) -> Result<Vec<Material>, InputError> {
    let mut out: Vec<Material> = vec![];
    for (i, m) in sf.materials.iter().enumerate() {
        // beyond 10²⁰ kg/m³ (a neutron star's 10¹⁷) or below 10⁻²⁰, inverse masses,
        // Delassus blocks or impulses fall among the subnormal numbers, where
        // arithmetic crawls
        if !(1e-20..=1e20).contains(&m.density) {
            return Err(cx.err(
                &[k("materials"), Seg::Index(i), k("density")],
                format!("density must lie in [1e-20, 1e20] kg/m³, got {:e}", m.density),
            ));
        }
        if out.iter().any(|o| o.name == m.name) {
            return Err(cx.err(
                &[k("materials"), Seg::Index(i), k("name")],
                format!("material `{}` is declared twice", m.name),
            ));
        }
        out.push(Material {
            name: m.name.clone(),
            density: m.density,
        });
    }
    Ok(out)
}

/// The law table and, beside it, the pairs declared `law = "none"` (never interact).
pub(crate) fn laws<B>(
    cx: &Ctx,
    sf: &SceneFile<B>,
    registry: &Registry,
    nm: usize,
    materials: &[Material],
    dimension: u8,
) -> Result<(Vec<Option<std::sync::Arc<dyn crate::law::Law>>>, Vec<bool>), InputError> {
    let mut table = vec![None; nm * nm];
    let mut declared = vec![false; nm * nm];
    for (i, l) in sf.laws.iter().enumerate() {
        let base = [k("laws"), Seg::Index(i)];
        let def = if l.law == "none" {
            None
        } else {
            Some(registry.laws.get(l.law.as_str()).ok_or_else(|| {
                cx.err(
                    &at(&base, &[k("law")]),
                    format!("unknown law `{}`; installed: none, {}", l.law, registry.law_names().join(", ")),
                )
            })?)
        };
        let mut ids = [0u16; 2];
        for (s, name) in l.materials.iter().enumerate() {
            ids[s] = builder::material_id(materials, name)
                .ok_or_else(|| cx.err(&at(&base, &[k("materials"), Seg::Index(s)]), format!("unknown material `{name}`")))?;
        }
        let law = match def {
            Some(def) => Some((def.parse)(&l.params).map_err(|e| cx.err(&at(&base, &[k(&e.key)]), e.msg))?),
            None => {
                crate::params::only_keys(&l.params, &[]).map_err(|e| cx.err(&at(&base, &[k(&e.key)]), e.msg))?;
                None
            }
        };
        if dimension == 2 && law.as_ref().is_some_and(|x| x.bonds()) {
            return Err(cx.err(
                &at(&base, &[k("law")]),
                format!("`{}` bonds contacts through their areas, which no 2D detector reports yet (3D face contacts do); a 2D scene cannot use it", l.law),
            ));
        }
        let (a, c) = (ids[0] as usize, ids[1] as usize);
        if declared[a * nm + c] {
            return Err(cx.err(&at(&base, &[k("materials")]), "a law for this pair of materials is already given"));
        }
        for (x, y) in [(a, c), (c, a)] {
            table[x * nm + y] = law.clone();
            declared[x * nm + y] = true;
        }
    }
    Ok((table, declared))
}

/// A pressure (or servo) drive pushes a wall of the box sample along the wall's
/// own axis (x for the walls normal to x, …); anything else is refused, naming the
/// drive. `dofs`: the names of the drive's degrees of freedom; `section`: the
/// `[output]` key naming the box's walls.
pub(crate) fn check_pressure_drives(
    cx: &Ctx,
    drives: &[BodyDrive],
    box_walls: Option<&BoxWalls>,
    origins: &[Origin],
    dofs: &[&str],
    section: &str,
) -> Result<(), InputError> {
    let n = (dofs.len() + 1) / 2;
    for d in drives {
        for (dof, drv) in d.dof.iter().enumerate().take(dofs.len()) {
            if !drv.as_ref().is_some_and(|x| x.has_pressure()) {
                continue;
            }
            let wall = box_walls.and_then(|bw| bw.wall_of(d.body as usize, n));
            if wall.is_none_or(|wl| wl / 2 != dof) {
                let base = origin_path(origins[d.body as usize], "drive");
                return Err(cx.err(
                    &at(&base, &[k(dofs[dof])]),
                    format!("a pressure drive needs the body to be a wall of `[output] {section}`, driven along its own axis (x for the walls normal to x, ...)"),
                ));
            }
        }
    }
    Ok(())
}
