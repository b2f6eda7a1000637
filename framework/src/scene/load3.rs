//! Loading a 3D scene (`dimension = 3`): the same file format as in 2D with 3D
//! bodies (position (x, y, z), `rotation` as a rotation vector, velocity
//! (v, ω), drives of x, y, z, rx, ry, rz), 3D shapes and generators from the
//! registry, and `[output] box3` for box samples. Errors name the file, the line
//! and the key, as in 2D.

use super::builder::Origin;
use super::builder::SceneBuilder3;
use super::locate::Seg;
use super::schema::{BodySpec3, SceneFile};
use super::{
    alert_distance, at, check_overlaps, k, laws, laws_and_detectors, materials, parse, time_settings, validate_solver, BodyInfo, Ctx,
    OutputSettings,
};
use crate::detect::{Detector, DetectorTable};
use crate::dim::D3;
use crate::drive::BodyDrive;
use crate::error::InputError;
use crate::registry::{ParamError, Registry};
use crate::rigid2d::bodies::ShapeRef;
use crate::world::{BoxWalls, World3};

/// A loaded 3D scene: the world and how to write it.
pub type Scene3 = super::Scene<D3>;

/// Loads a 3D scene from its text; `file` names it in messages.
pub fn load_str(text: &str, file: &str, registry: &Registry) -> Result<Scene3, InputError> {
    load_str_with(text, file, registry, false).map(|(s, _)| s)
}

/// [`load_str`] that also returns the scene's `[[deformable]]` entries for a
/// deformable-body plugin (refused with `deformable = false`, as in 2D).
pub fn load_str_with(text: &str, file: &str, registry: &Registry, deformable: bool) -> Result<(Scene3, Vec<toml::Table>), InputError> {
    let mut sf: SceneFile<BodySpec3> = parse(text, file)?;
    let cx = Ctx {
        text,
        file,
        deformable: !sf.deformable.is_empty(),
    };
    if !deformable && cx.deformable {
        return Err(cx.err(&[k("deformable")], super::NO_DEFORMABLE));
    }
    let entries = std::mem::take(&mut sf.deformable);
    let gravity = match sf.gravity.as_deref() {
        None => [0.0, 0.0, -9.81],
        Some(&[x, y, z]) if [x, y, z].iter().all(|g| g.is_finite()) => [x, y, z],
        Some(_) => return Err(cx.err(&[k("gravity")], "gravity must be 3 finite numbers in 3D")),
    };
    if sf.output.box_walls.is_some() {
        return Err(cx.err(&[k("output"), k("box")], "`box` names the 4 walls of a 2D sample; in 3D use `box3`"));
    }
    let time = time_settings(&cx, &sf)?;
    validate_solver(&cx, &sf.solver)?;
    let mats = materials(&cx, &sf)?;
    let nm = mats.len();
    let (laws, declared) = laws(&cx, &sf, registry, nm, &mats, 3)?;
    let mut b = SceneBuilder3::new(registry, mats);
    let mut drives = vec![];
    add_bodies(&cx, &sf, &mut b, &mut drives)?;
    for (g, spec) in sf.generate.iter().enumerate() {
        let base = [k("generate"), Seg::Index(g)];
        let gen = registry.tables::<D3>().generators.get(spec.kind.as_str()).ok_or_else(|| {
            cx.err(
                &at(&base, &[k("kind")]),
                format!(
                    "unknown 3D generator `{}`; installed: {}",
                    spec.kind,
                    registry.generator_names::<D3>().join(", ")
                ),
            )
        })?;
        b.origin = Origin::Generated(g);
        gen.generate(&spec.params, &mut b)
            .map_err(|e: ParamError| cx.err(&at(&base, &[k(&e.key)]), e.msg))?;
    }
    drives.append(&mut b.drives);
    if b.bodies.is_empty() {
        return Err(cx.err(&[], "the scene has no bodies"));
    }
    let n = b.bodies.len();
    let driven: Vec<bool> = (0..n).map(|i| drives.iter().any(|d: &BodyDrive| d.body as usize == i)).collect();
    let info: Vec<BodyInfo> = (0..n)
        .map(|i| BodyInfo {
            material: b.bodies.material[i] as usize,
            kind: b.bodies.shape[i].kind as usize,
            movable: b.bodies.movable(i) || driven[i],
            origin: b.origins[i],
        })
        .collect();
    let kinds: Vec<&'static str> = b.shapes.iter().map(|x| x.kind()).collect();
    let table = DetectorTable {
        nk: kinds.len(),
        table: laws_and_detectors(&cx, &info, &b.materials, &kinds, &laws, &declared, |x, y| {
            registry.detector::<D3>(x, y)
        })?,
    };
    let sizes: Vec<f64> = (0..n)
        .map(|i| b.shapes[b.bodies.shape[i].kind as usize].size(b.bodies.shape[i].index))
        .collect();
    let alert = alert_distance(&cx, &sf.detection, &sizes)?;
    let mut raw = vec![];
    Detector::default().detect(&b.bodies, &b.shapes, &table, 0.0, &mut raw);
    let contacts = raw.iter().map(|rc| (rc.i as usize, rc.j as usize, rc.gap));
    let material = |x: usize| b.bodies.material[x] as usize;
    check_overlaps(&cx, &sf.detection, contacts, &sizes, &laws, nm, material, &b.names, &b.origins)?;
    let box_walls = match &sf.output.box3 {
        None => None,
        Some(bs) => {
            let find = |key: &str, name: &str| {
                b.names
                    .iter()
                    .position(|x| x.as_deref() == Some(name))
                    .map(|p| p as u32)
                    .ok_or_else(|| cx.err(&[k("output"), k("box3"), k(key)], format!("no body is named `{name}`")))
            };
            Some(BoxWalls {
                walls: [
                    find("xmin", &bs.xmin)?,
                    find("xmax", &bs.xmax)?,
                    find("ymin", &bs.ymin)?,
                    find("ymax", &bs.ymax)?,
                    find("zmin", &bs.zmin)?,
                    find("zmax", &bs.zmax)?,
                ],
                strain_from: bs.strain_from,
            })
        }
    };
    super::check_pressure_drives(
        &cx,
        &drives,
        box_walls.as_ref(),
        &b.origins,
        &["x", "y", "z", "rx", "ry", "rz"],
        "box3",
    )?;
    for (i, w) in sf.output.writers.iter().enumerate() {
        if registry.writer::<D3>(w).is_none() {
            return Err(cx.err(&[k("output"), k("writers"), Seg::Index(i)], format!("unknown writer `{w}`")));
        }
    }
    let movable = (0..n).filter(|&i| b.bodies.movable(i)).count();
    let decomposition = match &sf.decomposition {
        None => None,
        Some(d) => Some(super::decomposition(&cx, d, movable)?),
    };
    let world = World3 {
        bodies: b.bodies,
        names: b.names,
        shapes: b.shapes,
        materials: b.materials,
        laws,
        drives,
        fixed: b.fixed,
        gravity,
        time,
        solver: sf.solver,
        alert,
        box_walls,
        box_h0: None,
        detectors: table,
        t: 0.0,
        step: 0,
        contacts: Default::default(),
        reaction: vec![[0.0; 6]; n],
        scratch: Default::default(),
    };
    Ok((
        Scene3 {
            world,
            output: OutputSettings {
                every: sf.output.every,
                vtk: sf.output.vtk,
                writers: sf.output.writers,
                checkpoint_every: sf.output.checkpoint_every,
            },
            decomposition,
        },
        entries,
    ))
}

fn add_bodies(cx: &Ctx, sf: &SceneFile<BodySpec3>, b: &mut SceneBuilder3, drives: &mut Vec<BodyDrive>) -> Result<(), InputError> {
    for (i, spec) in sf.bodies.iter().enumerate() {
        let base = [k("bodies"), Seg::Index(i)];
        let p = |key: &str| at(&base, &[k(key)]);
        b.origin = Origin::Body(i);
        let kind = b.kind(&spec.shape).ok_or_else(|| {
            cx.err(
                &p("shape"),
                format!(
                    "unknown 3D shape `{}`; installed: {}",
                    spec.shape,
                    b.registry.shape_kinds::<D3>().join(", ")
                ),
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
        if spec
            .position
            .iter()
            .chain(&spec.velocity)
            .chain(&spec.rotation)
            .any(|x| !x.is_finite())
        {
            return Err(cx.err(&p("position"), "position, rotation and velocity must be finite"));
        }
        let id = b.add_body(ShapeRef { kind, index }, material, spec.position, spec.rotation, spec.velocity);
        let (m, inertia) = (b.bodies.mass[id as usize], b.bodies.inertia[id as usize]);
        if !(m > 0.0 && m.is_finite() && inertia.iter().all(|x| *x > 0.0 && x.is_finite())) {
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
            let named = [("x", &d.x), ("y", &d.y), ("z", &d.z), ("rx", &d.rx), ("ry", &d.ry), ("rz", &d.rz)];
            for (slot, (name, dd)) in named.into_iter().enumerate() {
                if let Some(dd) = dd {
                    dd.validate().map_err(|m| cx.err(&at(&base, &[k("drive"), k(name)]), m))?;
                    dof[slot] = Some(dd.clone());
                }
            }
            drives.push(BodyDrive { body: id, dof });
        }
    }
    Ok(())
}
