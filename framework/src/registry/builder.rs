//! Incremental construction of a scene (2D or 3D), used by the loader for explicit
//! bodies and by plugins' generators.

use crate::dim::{Dim, Vector, D2, D3};
use crate::drive::{BodyDrive, DofDrive};
use crate::model::{Bodies, ShapeRef};
use crate::registry::{ParamError, Registry, ShapeStore};
use crate::world::Material;
use std::collections::BTreeMap;

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
        }
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
        let need = (self.bodies.len() as f64 + count.max(0.0)) * per + extra.max(0.0);
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
        self.names.push(None);
        self.fixed.push(false);
        self.origins.push(self.origin);
        self.bodies.push(pos, q, vel, mp.mass, mp.inertia, mp.volume, shape, material)
    }

    /// Makes a body immovable.
    pub fn set_fixed(&mut self, b: u32) {
        self.fixed[b as usize] = true;
        self.bodies.set_fixed(b as usize);
    }

    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Position of body b.
    pub fn position(&self, b: u32) -> D::Point {
        self.bodies.pos[b as usize]
    }

    /// Drives the degrees of freedom of a body (2D: x, y, rot; 3D: x, y, z, rx,
    /// ry, rz; `None`: free). A generator that drives a body by velocity sets its
    /// initial velocity to the drive's value at t = 0 ([`Self::set_velocity`]).
    pub fn drive(&mut self, b: u32, dof: [Option<DofDrive>; 6]) {
        self.drives.push(BodyDrive { body: b, dof });
    }

    /// Sets a body's initial velocity (v, ω in world axes).
    pub fn set_velocity(&mut self, b: u32, vel: D::Twist) {
        self.bodies.vel[b as usize] = vel;
    }

    /// Sets a body's name (for outputs and `[output] box`).
    pub fn set_name(&mut self, b: u32, name: &str) {
        self.names[b as usize] = Some(name.to_string());
    }
}
