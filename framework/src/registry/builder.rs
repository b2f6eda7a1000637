//! Incremental construction of a scene (2D or 3D), used by the loader for explicit
//! bodies and by plugins' generators.

use crate::dim::{Coords, Dim, Vector, D2, D3};
use crate::drive::{BodyDrive, DofDrive};
use crate::model::{Bodies, ShapeRef};
use crate::registry::{ParamError, Registry, ShapeStore};
use crate::world::Material;
use std::collections::BTreeMap;
use std::hash::Hasher;

/// Which scene entry made a body (for messages).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Origin {
    /// `bodies[k]`
    Body(usize),
    /// `generate[k]`
    Generated(usize),
}

/// Material id by name (2D and 3D builders).
pub(crate) fn material_id(materials: &[Material], name: &str) -> Option<u16> {
    materials.iter().position(|m| m.name == name).map(|i| i as u16)
}

/// Material id named by the key `key` of `params`, or a clear error.
pub(crate) fn material_param(materials: &[Material], params: &toml::Table, key: &str) -> Result<u16, ParamError> {
    let name = params
        .get(key)
        .and_then(|v| v.as_str())
        .ok_or_else(|| ParamError::new(key, "missing material name"))?;
    material_id(materials, name).ok_or_else(|| ParamError::new(key, format!("unknown material `{name}`; declare it in [[materials]]")))
}

/// A rank's part of the scene ([`SceneBuilder::part`], issue 20): the builder holds
/// only the bodies `keep` accepts (given each body's global id and bounding box,
/// first `D::N` coordinates), and keeps of every body of the scene what the loader's
/// whole-scene checks and the ranks' first grid read (≈ 60 B a body, dropped after
/// loading).
pub struct Part {
    pub(crate) keep: Box<dyn Fn(u32, &[[f64; 3]; 2]) -> bool>,
    /// The share of the scene's bodies a rank holds, for the memory estimate of
    /// [`SceneBuilder::reserve`] (0 for the survey, which holds none; 1/P for a
    /// rank's part, its halo left out).
    pub(crate) share: f64,
    /// A hash of what the columns leave out (orientations, velocities, names,
    /// drives, box walls): the ranks' agreement on the scene.
    pub(crate) hash: std::collections::hash_map::DefaultHasher,
    /// Global ids of the bodies held (ascending: the held bodies' slots).
    pub(crate) globals: Vec<u32>,
    /// Per scene body, by global id.
    pub(crate) centre: Vec<[f64; 3]>,
    pub(crate) mass: Vec<f64>,
    pub(crate) rho2: Vec<f64>,
    pub(crate) volume: Vec<f64>,
    pub(crate) shape: Vec<ShapeRef>,
    pub(crate) material: Vec<u16>,
    pub(crate) movable: Vec<bool>,
    /// The bodies with unbounded boxes, and the named ones with their names.
    pub(crate) unbounded: Vec<u32>,
    pub(crate) named: Vec<(u32, String)>,
    /// The driven bodies (set once the scene is loaded).
    pub(crate) driven: Vec<u32>,
}

impl Part {
    pub(crate) fn new(keep: Box<dyn Fn(u32, &[[f64; 3]; 2]) -> bool>, share: f64) -> Part {
        Part {
            keep,
            share,
            hash: Default::default(),
            globals: vec![],
            centre: vec![],
            mass: vec![],
            rho2: vec![],
            volume: vec![],
            shape: vec![],
            material: vec![],
            movable: vec![],
            unbounded: vec![],
            named: vec![],
            driven: vec![],
        }
    }
}

/// Bytes a body's [`Part`] columns take (centre, mass, ρ², volume, shape,
/// material, whether it moves, and its origin).
const PART_COLUMNS: f64 = 80.0;

/// Bodies under construction, with the shape stores of the kinds they use.
pub struct SceneBuilder<'r, D: Dim> {
    pub(crate) registry: &'r Registry,
    pub(crate) bodies: Bodies<D>,
    pub(crate) names: Vec<Option<String>>,
    pub(crate) fixed: Vec<bool>,
    pub(crate) shapes: Vec<Box<dyn ShapeStore<D>>>,
    pub(crate) kind_ids: BTreeMap<&'static str, u16>,
    pub(crate) materials: Vec<Material>,
    pub(crate) origins: Vec<Origin>,
    pub(crate) origin: Origin,
    pub(crate) drives: Vec<BodyDrive>,
    /// A rank's part ([`Part`]); `None`: every body held (`bodies`, `names` and
    /// `fixed` are then by global id; with a part, by the held bodies' slots, and
    /// `origins` and `drives` by global id in both).
    pub(crate) part: Option<Part>,
}

/// The 2D builder.
pub type SceneBuilder2<'r> = SceneBuilder<'r, D2>;
/// The 3D builder.
pub type SceneBuilder3<'r> = SceneBuilder<'r, D3>;

impl<'r, D: Dim> SceneBuilder<'r, D> {
    pub(crate) fn new(registry: &'r Registry, materials: Vec<Material>) -> Self {
        SceneBuilder {
            registry,
            bodies: Bodies::default(),
            names: vec![],
            fixed: vec![],
            shapes: vec![],
            kind_ids: BTreeMap::new(),
            materials,
            origins: vec![],
            origin: Origin::Body(0),
            drives: vec![],
            part: None,
        }
    }

    /// The slot of body `g` (a global id) if the builder holds it.
    pub(crate) fn slot(&self, g: u32) -> Option<usize> {
        match &self.part {
            None => ((g as usize) < self.bodies.len()).then_some(g as usize),
            Some(p) => p.globals.binary_search(&g).ok(),
        }
    }

    /// Mass, ρ², volume, shape, material and whether impulses move it, of body `g`
    /// (held or not).
    pub(crate) fn mass_of(&self, g: usize) -> f64 {
        self.part.as_ref().map_or_else(|| self.bodies.mass[g], |p| p.mass[g])
    }
    pub(crate) fn shape_of(&self, g: usize) -> ShapeRef {
        self.part.as_ref().map_or_else(|| self.bodies.shape[g], |p| p.shape[g])
    }
    pub(crate) fn material_of(&self, g: usize) -> u16 {
        self.part.as_ref().map_or_else(|| self.bodies.material[g], |p| p.material[g])
    }
    pub(crate) fn movable_of(&self, g: usize) -> bool {
        self.part.as_ref().map_or_else(|| self.bodies.movable(g), |p| p.movable[g])
    }

    /// Body `g`'s name, held or not.
    pub(crate) fn name_of(&self, g: usize) -> Option<&str> {
        match &self.part {
            None => self.names[g].as_deref(),
            Some(p) => p.named.iter().find(|x| x.0 as usize == g).map(|x| x.1.as_str()),
        }
    }

    /// The body named `name`, held or not.
    pub(crate) fn named(&self, name: &str) -> Option<u32> {
        match &self.part {
            None => self.names.iter().position(|n| n.as_deref() == Some(name)).map(|p| p as u32),
            Some(p) => p.named.iter().find(|x| x.1 == name).map(|x| x.0),
        }
    }

    /// The mass, inertia and volume a body of `shape` and `material` gets.
    pub(crate) fn mass_properties(&self, shape: ShapeRef, material: u16) -> crate::shape::MassProps<D> {
        let store = &self.shapes[shape.kind as usize];
        store.mass_properties(shape.index, self.materials[material as usize].density)
    }

    /// Material id by name.
    pub fn material(&self, name: &str) -> Option<u16> {
        material_id(&self.materials, name)
    }

    /// Material id of the key `key` of `params`, or a clear error.
    pub fn material_param(&self, params: &toml::Table, key: &str) -> Result<u16, ParamError> {
        material_param(&self.materials, params, key)
    }

    /// Kind id of a shape kind, creating its store on first use.
    pub fn kind(&mut self, name: &str) -> Option<u16> {
        if let Some(&k) = self.kind_ids.get(name) {
            return Some(k);
        }
        let (&static_name, def) = self.registry.tables::<D>().shapes.get_key_value(name)?;
        let id = self.shapes.len() as u16;
        self.shapes.push(def());
        self.kind_ids.insert(static_name, id);
        Some(id)
    }

    /// The store of a kind, downcast to the plugin's concrete type.
    pub fn store_mut<T: 'static>(&mut self, kind: u16) -> Option<&mut T> {
        self.shapes.get_mut(kind as usize)?.as_any_mut().downcast_mut::<T>()
    }

    pub fn store(&self, kind: u16) -> &dyn ShapeStore<D> {
        self.shapes[kind as usize].as_ref()
    }

    /// Adds a body whose shape is `shape` (already in its store), placed at `pos`
    /// with the orientation of the rotation vector `rot` (2D: the angle); mass and
    /// inertia come from the shape and the material's density. A shape not given
    /// in its principal frame is moved so that the body's position is its centre
    /// of mass ([`ShapeStore::principal_frame`]).
    /// Checks, before a generator allocates, that `count` more bodies and `extra`
    /// bytes of the generator's own working memory fit in the memory limit
    /// ([`super::limits`]); the error names `key` with the estimate. Generators call
    /// it with their counts (and grids) before building anything.
    pub fn reserve(&self, key: &str, count: f64, extra: f64) -> Result<(), ParamError> {
        let per = super::limits::bytes_per_body::<D>();
        let n = self.body_count() as f64 + count.max(0.0);
        // (a rank's part: every body's columns, and its share of the bodies)
        let need = match &self.part {
            None => n * per,
            Some(p) => n * (PART_COLUMNS + per * p.share),
        } + extra.max(0.0);
        let what = match (count > 0.0, extra > count * per) {
            (false, _) => "the generator's grid".to_string(),
            (true, false) => format!("{count} bodies"),
            (true, true) => format!("{count} bodies and the generator's grid"),
        };
        // beyond u32::MAX / 2 bodies the dense u32 ids run out, whatever the memory
        let max = self.registry.max_memory();
        if count <= u32::MAX as f64 / 2.0 && super::limits::check(need, max, &what).is_ok() {
            return Ok(());
        }
        let msg = super::limits::refusal(need, max, &what);
        Err(ParamError::new(key, format!("{msg}; make the sample smaller")))
    }

    pub fn add_body(&mut self, shape: ShapeRef, material: u16, pos: D::Point, rot: D::RotVec, vel: D::Twist) -> u32 {
        let store = &self.shapes[shape.kind as usize];
        let mp = store.mass_properties(shape.index, self.materials[material as usize].density);
        let (c, rc) = store.principal_frame(shape.index);
        let mut q = D::rot_from_vec(&rot);
        let mut pos = pos;
        if !c.is_zero() || rc != D::rot_identity() {
            let dc = D::rotate(&q, &c);
            pos = D::Point::from_fn(|k| pos[k] + dc[k]);
            q = D::rot_mul(&q, &rc);
        }
        let g = self.origins.len() as u32;
        self.origins.push(self.origin);
        if let Some(p) = self.part.as_mut() {
            // (the box of the orientation the body will hold)
            let rot = D::normalize_rot(q);
            let a = store.aabb(shape.index, pos, rot);
            rot.coords().iter().chain(vel.as_ref()).for_each(|x| p.hash.write_u64(x.to_bits()));
            let bx = a.corners3();
            let mut c = [0.0; 3];
            c[..D::N].copy_from_slice(pos.as_ref());
            p.centre.push(c);
            p.mass.push(mp.mass);
            p.rho2.push(D::rho2(mp.mass, &mp.inertia));
            p.volume.push(mp.volume);
            p.shape.push(shape);
            p.material.push(material);
            p.movable.push(true);
            if !a.is_bounded() {
                p.unbounded.push(g);
            }
            if !(p.keep)(g, &bx) {
                return g;
            }
            p.globals.push(g);
        }
        self.names.push(None);
        self.fixed.push(false);
        self.bodies.push(pos, q, vel, mp.mass, mp.inertia, mp.volume, shape, material);
        g
    }

    /// Makes a body immovable.
    pub fn set_fixed(&mut self, b: u32) {
        if let Some(p) = self.part.as_mut() {
            p.movable[b as usize] = false;
        }
        if let Some(k) = self.slot(b) {
            self.fixed[k] = true;
            self.bodies.set_fixed(k);
        }
    }

    /// The scene's bodies so far (held or not).
    pub fn body_count(&self) -> usize {
        self.origins.len()
    }

    /// Position of body b.
    pub fn position(&self, b: u32) -> D::Point {
        match &self.part {
            Some(p) => D::Point::from_fn(|k| p.centre[b as usize][k]),
            None => self.bodies.pos[b as usize],
        }
    }

    /// Drives the degrees of freedom of a body (2D: x, y, rot; 3D: x, y, z, rx,
    /// ry, rz; `None`: free). A generator that drives a body by velocity sets its
    /// initial velocity to the drive's value at t = 0 ([`Self::set_velocity`]).
    pub fn drive(&mut self, b: u32, dof: [Option<DofDrive>; 6]) {
        self.drives.push(BodyDrive { body: b, dof });
    }

    /// Sets a body's initial velocity (v, ω in world axes).
    pub fn set_velocity(&mut self, b: u32, vel: D::Twist) {
        if let Some(p) = self.part.as_mut() {
            p.hash.write_u32(b);
            vel.as_ref().iter().for_each(|x| p.hash.write_u64(x.to_bits()));
        }
        if let Some(k) = self.slot(b) {
            self.bodies.vel[k] = vel;
        }
    }

    /// Sets a body's name (for outputs and `[output] box`).
    pub fn set_name(&mut self, b: u32, name: &str) {
        if let Some(p) = self.part.as_mut() {
            p.named.push((b, name.to_string()));
            p.hash.write_u32(b);
            p.hash.write(name.as_bytes());
        }
        if let Some(k) = self.slot(b) {
            self.names[k] = Some(name.to_string());
        }
    }
}
