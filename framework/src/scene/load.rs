//! Building a [`Scene<D>`] from a parsed scene file, once for both dimensions: the
//! bodies, the generators, the laws and detectors, the initial overlaps, the box
//! sample and the drives, each error naming the file, the line and the key.

use super::builder::{Origin, Part, SceneBuilder};
use super::locate::Seg;
use super::schema::{BodySpec, SceneDim, SceneFile};
use super::{at, k, BodyInfo, Ctx, OutputSettings, Scene};
use crate::detect::{Detector, DetectorTable};
use crate::dim::{Coords, Dim, Vector};
use crate::drive::BodyDrive;
use crate::error::InputError;
use crate::model::ShapeRef;
use crate::registry::{ParamError, Registry};
use crate::world::held::WholeScene;
use crate::world::{BoxWalls, World};

/// The scene of a parsed file of dimension `D`.
pub(crate) fn load_parsed<D: SceneDim>(cx: &Ctx, sf: SceneFile<BodySpec<D>>, registry: &Registry) -> Result<Scene<D>, InputError> {
    load_parsed_part(cx, sf, registry, None).map(|x| x.0)
}

/// [`load_parsed`], holding only the bodies `part` keeps when it is given (a rank's
/// part, [`super::part`]): the whole-scene checks read every body's [`Part`]
/// columns, the world holds the part (its slots the kept global ids, the whole
/// scene's sums in [`WholeScene`]), and `part` comes back with every body's columns.
pub(crate) fn load_parsed_part<D: SceneDim>(
    cx: &Ctx,
    sf: SceneFile<BodySpec<D>>,
    registry: &Registry,
    part: Option<Part>,
) -> Result<(Scene<D>, Option<Part>), InputError> {
    let gravity = gravity::<D>(cx, &sf)?;
    if D::N == 2 && sf.decomposition.as_ref().is_some_and(|d| d.nz.is_some()) {
        return Err(cx.err(&[k("decomposition"), k("nz")], "`nz` splits along z: 3D scenes only"));
    }
    let time = super::time_settings(cx, &sf)?;
    let solver = super::solver_settings(cx, &sf.solver, gravity.as_ref())?;
    let materials = super::materials(cx, &sf)?;
    let mut b = SceneBuilder::<D>::new(registry, materials);
    b.part = part;
    let mut drives = vec![];
    add_bodies(cx, &sf, &mut b, &mut drives)?;
    generate(cx, &sf, registry, &mut b)?;
    drives.append(&mut b.drives);
    // a scene of a body family's bodies alone (deformable bodies) has no rigid ones
    if b.body_count() == 0 && !cx.families {
        return Err(cx.err(&[], "the scene has no bodies"));
    }
    check_masses(cx, &b)?;
    let nm = b.materials.len();
    let (laws, declared) = super::laws(cx, &sf, registry, nm, &b.materials, D::N as u8)?;
    if sf.solver.method != crate::solver::Method::Nlgs && laws.iter().flatten().any(|l| l.bonds()) {
        let msg = format!(
            "`{}` solves the unilateral contact problem only; the scene's bonded joints (mortar) need method = \"nlgs\"",
            sf.solver.method.name()
        );
        return Err(cx.err(&[k("solver"), k("method")], msg));
    }
    let n = b.body_count();
    let (table, sizes, alert) = detectors_and_alert(cx, &sf, registry, &b, &drives, (&laws, &declared))?;
    check_overlaps(cx, &sf, &b, &table, &sizes, &laws)?;
    let box_walls = box_walls::<D>(cx, &sf, |name| b.named(name))?;
    super::check_pressure_drives(cx, &drives, box_walls.as_ref(), &b.origins, D::DOF_NAMES, D::BOX_KEY)?;
    check_writers::<D>(cx, &sf, registry)?;
    let movable = (0..n).filter(|&i| b.movable_of(i)).count();
    let decomposition = match &sf.decomposition {
        None => None,
        Some(d) => Some(super::decomposition(cx, d, movable)?),
    };
    if let Some(p) = b.part.as_mut() {
        use std::hash::Hasher;
        p.driven = drives.iter().map(|d| d.body).collect();
        p.hash.write(format!("{drives:?} {box_walls:?}").as_bytes());
    }
    let (ids, whole, drives, box_walls) = match &b.part {
        None => (Default::default(), None, drives, box_walls),
        Some(p) => held_part::<D>(p, &b, drives, box_walls),
    };
    let held = b.bodies.len();
    let world = World {
        bodies: b.bodies,
        ids,
        names: b.names,
        shapes: b.shapes,
        materials: b.materials,
        laws,
        drives,
        fixed: b.fixed,
        gravity,
        time,
        solver,
        alert,
        box_walls,
        box_h0: None,
        detectors: table,
        t: 0.0,
        step: 0,
        contacts: Default::default(),
        reaction: vec![D::Twist::zero(); held],
        contact_shares: vec![],
        whole,
        scratch: Default::default(),
    };
    Ok((
        Scene {
            world,
            output: OutputSettings {
                every: sf.output.every,
                vtk: sf.output.vtk,
                writers: sf.output.writers,
                checkpoint_every: sf.output.checkpoint_every,
            },
            decomposition,
            families: vec![],
            dd_state: None,
            part: None,
            survey: None,
        },
        b.part,
    ))
}

/// Every pair of materials that can touch needs a law, every pair of kinds a
/// detector: the detector table, every body's size and the alert distance (every
/// body's, held or not).
#[allow(clippy::type_complexity)]
fn detectors_and_alert<D: SceneDim>(
    cx: &Ctx,
    sf: &SceneFile<BodySpec<D>>,
    registry: &Registry,
    b: &SceneBuilder<'_, D>,
    drives: &[BodyDrive],
    (laws, declared): (&[Option<std::sync::Arc<dyn crate::law::Law>>], &[bool]),
) -> Result<(DetectorTable<D>, Vec<f64>, f64), InputError> {
    let n = b.body_count();
    let kinds: Vec<&'static str> = b.shapes.iter().map(|x| x.kind()).collect();
    // the first two bodies (in id order) of each (material, kind, movable): all the
    // check reads (a material's first body, whether two are made of it), not N
    let nm = b.materials.len();
    let mut seen = vec![0u8; nm * kinds.len() * 2];
    let info: Vec<BodyInfo> = (0..n)
        .filter_map(|i| {
            let (material, kind) = (b.material_of(i) as usize, b.shape_of(i).kind as usize);
            let movable = b.movable_of(i) || drives.iter().any(|d: &BodyDrive| d.body as usize == i);
            let c = &mut seen[(kind * nm + material) * 2 + usize::from(movable)];
            *c = c.saturating_add(1);
            (*c <= 2).then_some(BodyInfo {
                material,
                kind,
                movable,
                origin: b.origins[i],
            })
        })
        .collect();
    let table = DetectorTable {
        nk: kinds.len(),
        table: super::laws_and_detectors(cx, &info, &b.materials, &kinds, laws, declared, |x, y| registry.detector::<D>(x, y))?,
    };
    let sizes: Vec<f64> = (0..n)
        .map(|i| b.shapes[b.shape_of(i).kind as usize].size(b.shape_of(i).index))
        .collect();
    let alert = super::alert_distance(cx, &sf.detection, &sizes)?;
    super::checks::check_alert_work(cx, alert, movable_centres(b), &sizes, D::N)?;
    Ok((table, sizes, alert))
}

/// Initial interpenetrations beyond the tolerance (a rank: among the bodies it
/// holds; every overlapping pair is held by the rank of the cell holding a point of
/// both).
fn check_overlaps<D: SceneDim>(
    cx: &Ctx,
    sf: &SceneFile<BodySpec<D>>,
    b: &SceneBuilder<'_, D>,
    table: &DetectorTable<D>,
    sizes: &[f64],
    laws: &[Option<std::sync::Arc<dyn crate::law::Law>>],
) -> Result<(), InputError> {
    let mut raw = vec![];
    Detector::default().detect(&b.bodies, &b.shapes, table, 0.0, &mut raw);
    let global = |k: u32| b.part.as_ref().map_or(k, |p| p.globals[k as usize]) as usize;
    let contacts = raw.iter().map(|rc| (global(rc.i), global(rc.j), rc.gap));
    let material = |x: usize| b.material_of(x) as usize;
    let name = |x: usize| b.name_of(x);
    let nm = b.materials.len();
    super::check_overlaps(cx, &sf.detection, contacts, sizes, laws, nm, material, &name, &b.origins)
}

/// The world's ids, the whole scene's sums, and the drives and box walls by slot,
/// of a part: every driven or named body is held (a rank keeps them), those of a
/// survey holding none are left out.
fn held_part<D: Dim>(
    p: &Part,
    b: &SceneBuilder<'_, D>,
    drives: Vec<BodyDrive>,
    box_walls: Option<BoxWalls>,
) -> (crate::model::BodyIds, Option<WholeScene>, Vec<BodyDrive>, Option<BoxWalls>) {
    let n = p.centre.len();
    let slot = |g: u32| p.globals.binary_search(&g).ok().map(|k| k as u32);
    let ids = crate::model::BodyIds::default()
        .respread(p.globals.clone(), n as u32)
        .expect("held bodies ascend in global id");
    // as `World::whole_of_held` adds them, in id order
    let mut w = WholeScene {
        grain_volume: -0.0,
        ..Default::default()
    };
    for g in 0..n {
        let s = p.shape[g];
        let store = &b.shapes[s.kind as usize];
        if store.is_grain() && p.movable[g] && !drives.iter().any(|d| d.body as usize == g) {
            w.grains += 1;
            w.grain_volume += p.volume[g];
            w.max_grain_size = w.max_grain_size.max(store.size(s.index));
        }
    }
    (w.movable, w.rho2) = (p.movable.clone(), p.rho2.clone());
    let drives = drives
        .into_iter()
        .filter_map(|mut d| {
            d.body = slot(d.body)?;
            Some(d)
        })
        .collect();
    let box_walls = box_walls.and_then(|mut bw| {
        // (the unused walls of a 2D box stay u32::MAX)
        for k in bw.walls.iter_mut().filter(|k| (**k as usize) < n) {
            *k = slot(*k)?;
        }
        Some(bw)
    });
    (ids, Some(w), drives, box_walls)
}

/// Every writer of `[output] writers` is registered for the dimension.
fn check_writers<D: SceneDim>(cx: &Ctx, sf: &SceneFile<BodySpec<D>>, registry: &Registry) -> Result<(), InputError> {
    for (i, w) in sf.output.writers.iter().enumerate() {
        if registry.writer::<D>(w).is_none() {
            return Err(cx.err(&[k("output"), k("writers"), Seg::Index(i)], format!("unknown writer `{w}`")));
        }
    }
    Ok(())
}

/// `gravity`: D finite numbers; by default 9.81 m/s² along −y (2D) or −z (3D).
fn gravity<D: SceneDim>(cx: &Ctx, sf: &SceneFile<BodySpec<D>>) -> Result<D::Point, InputError> {
    match sf.gravity.as_deref() {
        None => Ok(D::Point::from_fn(|a| if a + 1 == D::N { -9.81 } else { 0.0 })),
        Some(g) if g.len() == D::N && g.iter().all(|x| x.is_finite()) => Ok(D::Point::from_fn(|a| g[a])),
        Some(_) => Err(cx.err(&[k("gravity")], format!("gravity must be {} finite numbers in {}", D::N, D::NAME))),
    }
}

/// The bodies of `[[generate]]`, by the registered generators.
fn generate<D: SceneDim>(cx: &Ctx, sf: &SceneFile<BodySpec<D>>, registry: &Registry, b: &mut SceneBuilder<D>) -> Result<(), InputError> {
    for (g, spec) in sf.generate.iter().enumerate() {
        let base = [k("generate"), Seg::Index(g)];
        let gen = registry.tables::<D>().generators.get(spec.kind.as_str()).ok_or_else(|| {
            let installed = registry.generator_names::<D>().join(", ");
            let msg = format!("unknown {} generator `{}`; installed: {installed}", D::NAME, spec.kind);
            cx.err(&at(&base, &[k("kind")]), msg)
        })?;
        b.origin = Origin::Generated(g);
        gen.generate(&spec.params, b)
            .map_err(|e: ParamError| cx.err(&at(&base, &[k(&e.key)]), e.msg))?;
    }
    Ok(())
}

/// `[output] box` (2D) / `box3` (3D): the walls of a box sample, by body name
/// (the other dimension's key refused).
fn box_walls<D: SceneDim>(
    cx: &Ctx,
    sf: &SceneFile<BodySpec<D>>,
    named: impl Fn(&str) -> Option<u32>,
) -> Result<Option<BoxWalls>, InputError> {
    let other_box = match D::N {
        2 => sf.output.box3.is_some(),
        _ => sf.output.box_walls.is_some(),
    };
    if other_box {
        let msg = format!(
            "`{}` names the walls of a box sample in the other dimension; in {} use `{}`",
            D::OTHER_BOX_KEY,
            D::NAME,
            D::BOX_KEY
        );
        return Err(cx.err(&[k("output"), k(D::OTHER_BOX_KEY)], msg));
    }
    let Some((keys, strain_from)) = D::box_walls(&sf.output) else {
        return Ok(None);
    };
    let mut walls = [u32::MAX; 6];
    for (slot, (key, name)) in keys.into_iter().enumerate() {
        walls[slot] = named(name).ok_or_else(|| cx.err(&[k("output"), k(D::BOX_KEY), k(key)], format!("no body is named `{name}`")))?;
    }
    Ok(Some(BoxWalls { walls, strain_from }))
}

fn add_bodies<D: SceneDim>(
    cx: &Ctx,
    sf: &SceneFile<BodySpec<D>>,
    b: &mut SceneBuilder<D>,
    drives: &mut Vec<BodyDrive>,
) -> Result<(), InputError> {
    for (i, spec) in sf.bodies.iter().enumerate() {
        let base = [k("bodies"), Seg::Index(i)];
        let p = |key: &str| at(&base, &[k(key)]);
        b.origin = Origin::Body(i);
        let kind = b.kind(&spec.shape).ok_or_else(|| {
            let installed = b.registry.shape_kinds::<D>().join(", ");
            cx.err(
                &p("shape"),
                format!("unknown {} shape `{}`; installed: {installed}", D::NAME, spec.shape),
            )
        })?;
        let material = b.material(&spec.material).ok_or_else(|| {
            cx.err(
                &p("material"),
                format!("unknown material `{}`; declare it in [[materials]]", spec.material),
            )
        })?;
        let index = b.shapes[kind as usize]
            .push_params(&spec.params)
            .map_err(|e| cx.err(&p(&e.key), e.msg))?;
        let values = spec
            .position
            .as_ref()
            .iter()
            .chain(spec.velocity.as_ref())
            .chain(spec.rotation.coords());
        if values.clone().any(|x| !x.is_finite()) {
            return Err(cx.err(&p("position"), "position, rotation and velocity must be finite"));
        }
        let id = b.add_body(ShapeRef { kind, index }, material, spec.position, spec.rotation, spec.velocity);
        let mp = b.mass_properties(ShapeRef { kind, index }, material);
        let (m, inertia) = (mp.mass, mp.inertia);
        if !(m > 0.0 && m.is_finite() && inertia.coords().iter().all(|x| *x > 0.0 && x.is_finite())) {
            return Err(cx.err(
                &p("shape"),
                format!("the body's mass ({m}) and inertia ({inertia:?}) must be positive and finite"),
            ));
        }
        if let Some(name) = &spec.name {
            if b.named(name).is_some() {
                return Err(cx.err(&p("name"), format!("two bodies are named `{name}`")));
            }
            b.set_name(id, name);
        }
        if spec.fixed {
            if spec.drive.is_some() {
                return Err(cx.err(&p("drive"), "a fixed body cannot also be driven"));
            }
            b.set_fixed(id);
        }
        if let Some(d) = &spec.drive {
            let mut dof: [Option<crate::drive::DofDrive>; 6] = Default::default();
            for (slot, dd) in D::drives(d).into_iter().enumerate() {
                if let Some(dd) = dd {
                    dd.validate()
                        .map_err(|m| cx.err(&at(&base, &[k("drive"), k(D::DOF_NAMES[slot])]), m))?;
                    dof[slot] = Some(dd.clone());
                }
            }
            drives.push(BodyDrive { body: id, dof });
        }
    }
    Ok(())
}

/// A movable body needs a mass (a shape of 1e-308 m has none left).
fn check_masses<D: Dim>(cx: &Ctx, b: &SceneBuilder<'_, D>) -> Result<(), InputError> {
    let m = |i: usize| b.mass_of(i);
    match (0..b.body_count()).find(|&i| b.movable_of(i) && !(m(i) > 0.0 && m(i).is_finite())) {
        None => Ok(()),
        Some(i) => Err(cx.err(
            &super::origin_path(b.origins[i], "shape"),
            format!(
                "a movable body of mass {:e} kg (its shape's volume times its density): make the shape larger or the body fixed",
                m(i)
            ),
        )),
    }
}

/// The movable bodies' centres (z = 0 in 2D).
fn movable_centres<'a, D: Dim>(b: &'a SceneBuilder<'_, D>) -> impl Iterator<Item = [f64; 3]> + 'a {
    (0..b.body_count()).filter(|&i| b.movable_of(i)).map(|i| {
        let mut p = [0.0; 3];
        for (x, y) in p.iter_mut().zip(b.position(i as u32).as_ref()) {
            *x = *y;
        }
        p
    })
}
