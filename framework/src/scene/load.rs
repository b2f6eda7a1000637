//! Building a [`Scene<D>`] from a parsed scene file, once for both dimensions: the
//! bodies, the generators, the laws and detectors, the initial overlaps, the box
//! sample and the drives, each error naming the file, the line and the key.

use super::builder::{Origin, SceneBuilder};
use super::locate::Seg;
use super::schema::{BodySpec, SceneDim, SceneFile};
use super::{at, k, BodyInfo, Ctx, OutputSettings, Scene};
use crate::detect::{Detector, DetectorTable};
use crate::dim::{Coords, Dim, Vector};
use crate::drive::BodyDrive;
use crate::error::InputError;
use crate::model::ShapeRef;
use crate::registry::{ParamError, Registry};
use crate::world::{BoxWalls, World};

/// The scene of a parsed file of dimension `D`.
pub(crate) fn load_parsed<D: SceneDim>(cx: &Ctx, sf: SceneFile<BodySpec<D>>, registry: &Registry) -> Result<Scene<D>, InputError> {
    let gravity = gravity::<D>(cx, &sf)?;
    if D::N == 2 && sf.decomposition.as_ref().is_some_and(|d| d.nz.is_some()) {
        return Err(cx.err(&[k("decomposition"), k("nz")], "`nz` splits along z: 3D scenes only"));
    }
    let time = super::time_settings(cx, &sf)?;
    let solver = super::solver_settings(cx, &sf.solver, gravity.as_ref())?;
    let materials = super::materials(cx, &sf)?;
    let mut b = SceneBuilder::<D>::new(registry, materials);
    let mut drives = vec![];
    add_bodies(cx, &sf, &mut b, &mut drives)?;
    generate(cx, &sf, registry, &mut b)?;
    drives.append(&mut b.drives);
    // a scene of a body family's bodies alone (deformable bodies) has no rigid ones
    if b.bodies.is_empty() && !cx.families {
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
    // every pair of materials that can touch needs a law; every pair of kinds a detector
    let n = b.bodies.len();
    let info: Vec<BodyInfo> = (0..n)
        .map(|i| BodyInfo {
            material: b.bodies.material[i] as usize,
            kind: b.bodies.shape[i].kind as usize,
            movable: b.bodies.movable(i) || drives.iter().any(|d: &BodyDrive| d.body as usize == i),
            origin: b.origins[i],
        })
        .collect();
    let kinds: Vec<&'static str> = b.shapes.iter().map(|x| x.kind()).collect();
    let table = DetectorTable {
        nk: kinds.len(),
        table: super::laws_and_detectors(cx, &info, &b.materials, &kinds, &laws, &declared, |x, y| {
            registry.detector::<D>(x, y)
        })?,
    };
    let sizes: Vec<f64> = (0..n)
        .map(|i| b.shapes[b.bodies.shape[i].kind as usize].size(b.bodies.shape[i].index))
        .collect();
    let alert = super::alert_distance(cx, &sf.detection, &sizes)?;
    super::checks::check_alert_work(cx, alert, &movable_centres(&b), &sizes, D::N)?;
    // initial interpenetrations beyond the tolerance
    let mut raw = vec![];
    Detector::default().detect(&b.bodies, &b.shapes, &table, 0.0, &mut raw);
    let contacts = raw.iter().map(|rc| (rc.i as usize, rc.j as usize, rc.gap));
    let material = |x: usize| b.bodies.material[x] as usize;
    super::check_overlaps(cx, &sf.detection, contacts, &sizes, &laws, nm, material, &b.names, &b.origins)?;
    let box_walls = box_walls::<D>(cx, &sf, &b.names)?;
    super::check_pressure_drives(cx, &drives, box_walls.as_ref(), &b.origins, D::DOF_NAMES, D::BOX_KEY)?;
    check_writers::<D>(cx, &sf, registry)?;
    let movable = (0..n).filter(|&i| b.bodies.movable(i)).count();
    let decomposition = match &sf.decomposition {
        None => None,
        Some(d) => Some(super::decomposition(cx, d, movable)?),
    };
    let world = World {
        bodies: b.bodies,
        ids: Default::default(),
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
        reaction: vec![D::Twist::zero(); n],
        contact_shares: vec![],
        whole: None,
        scratch: Default::default(),
    };
    Ok(Scene {
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
    })
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
fn box_walls<D: SceneDim>(cx: &Ctx, sf: &SceneFile<BodySpec<D>>, names: &[Option<String>]) -> Result<Option<BoxWalls>, InputError> {
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
        walls[slot] = names
            .iter()
            .position(|n| n.as_deref() == Some(name))
            .map(|p| p as u32)
            .ok_or_else(|| cx.err(&[k("output"), k(D::BOX_KEY), k(key)], format!("no body is named `{name}`")))?;
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
        let (m, inertia) = (b.bodies.mass[id as usize], b.bodies.inertia[id as usize]);
        if !(m > 0.0 && m.is_finite() && inertia.coords().iter().all(|x| *x > 0.0 && x.is_finite())) {
            return Err(cx.err(
                &p("shape"),
                format!("the body's mass ({m}) and inertia ({inertia:?}) must be positive and finite"),
            ));
        }
        if let Some(name) = &spec.name {
            if b.names.iter().any(|x| x.as_deref() == Some(name.as_str())) {
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
    let m = &b.bodies.mass;
    match (0..b.bodies.len()).find(|&i| b.bodies.movable(i) && !(m[i] > 0.0 && m[i].is_finite())) {
        None => Ok(()),
        Some(i) => Err(cx.err(
            &super::origin_path(b.origins[i], "shape"),
            format!(
                "a movable body of mass {:e} kg (its shape's volume times its density): make the shape larger or the body fixed",
                m[i]
            ),
        )),
    }
}

/// The movable bodies' centres (z = 0 in 2D).
fn movable_centres<D: Dim>(b: &SceneBuilder<'_, D>) -> Vec<[f64; 3]> {
    (0..b.bodies.len())
        .filter(|&i| b.bodies.movable(i))
        .map(|i| {
            let mut p = [0.0; 3];
            for (x, y) in p.iter_mut().zip(b.bodies.pos[i].as_ref()) {
                *x = *y;
            }
            p
        })
        .collect()
}
