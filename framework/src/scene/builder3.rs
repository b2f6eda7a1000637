//! Incremental construction of a 3D scene, used by the loader for explicit bodies
//! and by plugins' 3D generators.

use super::builder::Origin;
use crate::drive::DofDrive;
use crate::registry::{ParamError, Registry};
use crate::registry3::ShapeStore3;
use crate::rigid2d::bodies::ShapeRef;
use crate::rigid3d::bodies::from_rotation_vector;
use crate::rigid3d::Bodies3;
use crate::world::Material;
use crate::world3::BodyDrive3;
use std::collections::BTreeMap;

/// 3D bodies under construction, with the shape stores of the kinds they use.
pub struct SceneBuilder3<'r> {
    pub(crate) registry: &'r Registry,
    pub(crate) bodies: Bodies3,
    pub(crate) names: Vec<Option<String>>,
    pub(crate) fixed: Vec<bool>,
    pub(crate) shapes: Vec<Box<dyn ShapeStore3>>,
    pub(crate) kind_ids: BTreeMap<&'static str, u16>,
    pub(crate) materials: Vec<Material>,
    pub(crate) origins: Vec<Origin>,
    pub(crate) origin: Origin,
    pub(crate) drives: Vec<BodyDrive3>,
}

impl<'r> SceneBuilder3<'r> {
    pub(crate) fn new(registry: &'r Registry, materials: Vec<Material>) -> Self {
        SceneBuilder3 {
            registry,
            bodies: Bodies3::default(),
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
        super::builder::material_id(&self.materials, name)
    }

    /// Material id of the key `key` of `params`, or a clear error.
    pub fn material_param(&self, params: &toml::Table, key: &str) -> Result<u16, ParamError> {
        super::builder::material_param(&self.materials, params, key)
    }

    /// Kind id of a 3D shape kind, creating its store on first use.
    pub fn kind(&mut self, name: &str) -> Option<u16> {
        if let Some(&k) = self.kind_ids.get(name) {
            return Some(k);
        }
        let (&static_name, def) = self.registry.shapes3.get_key_value(name)?;
        let id = self.shapes.len() as u16;
        self.shapes.push((def.new_store)());
        self.kind_ids.insert(static_name, id);
        Some(id)
    }

    /// The store of a kind, downcast to the plugin's concrete type.
    pub fn store_mut<T: 'static>(&mut self, kind: u16) -> Option<&mut T> {
        self.shapes.get_mut(kind as usize)?.as_any_mut().downcast_mut::<T>()
    }

    pub fn store(&self, kind: u16) -> &dyn ShapeStore3 {
        self.shapes[kind as usize].as_ref()
    }

    /// Adds a body whose shape is `shape` (already in its store); mass and inertia
    /// from the shape and the material's density; orientation as a rotation vector.
    pub fn add_body(&mut self, shape: ShapeRef, material: u16, pos: [f64; 3], rotation: [f64; 3], vel: [f64; 6]) -> u32 {
        let store = &self.shapes[shape.kind as usize];
        let mp = store.mass_properties(shape.index, self.materials[material as usize].density);
        let (c, qc) = store.principal_frame(shape.index);
        let mut q = from_rotation_vector(rotation);
        let mut pos = pos;
        if (c, qc) != ([0.0; 3], [1.0, 0.0, 0.0, 0.0]) {
            let dc = crate::rigid3d::bodies::rotate(q, c);
            pos = [pos[0] + dc[0], pos[1] + dc[1], pos[2] + dc[2]];
            q = crate::rigid3d::bodies::normalize(crate::rigid3d::bodies::quat_mul(q, qc));
        }
        self.names.push(None);
        self.fixed.push(false);
        self.origins.push(self.origin);
        self.bodies.push(pos, q, vel, mp.mass, mp.inertia, mp.volume, shape, material)
    }

    /// Makes a body immovable.
    pub fn set_fixed(&mut self, b: u32) {
        self.fixed[b as usize] = true;
        self.bodies.free[b as usize] = 0;
        self.bodies.refresh_inverse(b as usize);
    }

    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    pub fn position(&self, b: u32) -> [f64; 3] {
        self.bodies.pos[b as usize]
    }

    /// Drives the degrees of freedom of a body (x, y, z, rx, ry, rz; `None`: free).
    /// A generator that drives a body by velocity sets its initial velocity to
    /// the drive's value at t = 0 ([`Self::set_velocity`]).
    pub fn drive(&mut self, b: u32, dof: [Option<DofDrive>; 6]) {
        self.drives.push(BodyDrive3 { body: b, dof });
    }

    /// Sets a body's initial velocity (v, ω in world axes).
    pub fn set_velocity(&mut self, b: u32, vel: [f64; 6]) {
        self.bodies.vel[b as usize] = vel;
    }

    /// Sets a body's name (for outputs and `[output] box3`).
    pub fn set_name(&mut self, b: u32, name: &str) {
        self.names[b as usize] = Some(name.to_string());
    }
}
