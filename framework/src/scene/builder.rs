//! Incremental construction of a 2D scene, used by the loader for explicit bodies
//! and by plugins' generators.

use crate::registry::{ParamError, Registry, ShapeStore2};
use crate::rigid2d::bodies::ShapeRef;
use crate::rigid2d::Bodies2;
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
pub struct SceneBuilder2<'r> {
    pub(crate) registry: &'r Registry,
    pub(crate) bodies: Bodies2,
    pub(crate) names: Vec<Option<String>>,
    pub(crate) shapes: Vec<Box<dyn ShapeStore2>>,
    pub(crate) kind_ids: BTreeMap<&'static str, u16>,
    pub(crate) materials: Vec<Material>,
    pub(crate) origins: Vec<Origin>,
    pub(crate) origin: Origin,
}

impl<'r> SceneBuilder2<'r> {
    pub(crate) fn new(registry: &'r Registry, materials: Vec<Material>) -> Self {
        SceneBuilder2 {
            registry,
            bodies: Bodies2::default(),
            names: vec![],
            shapes: vec![],
            kind_ids: BTreeMap::new(),
            materials,
            origins: vec![],
            origin: Origin::Body(0),
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
        let (&static_name, def) = self.registry.shapes.get_key_value(name)?;
        let id = self.shapes.len() as u16;
        self.shapes.push((def.new_store)());
        self.kind_ids.insert(static_name, id);
        Some(id)
    }

    /// The store of a kind, downcast to the plugin's concrete type.
    pub fn store_mut<T: 'static>(&mut self, kind: u16) -> Option<&mut T> {
        self.shapes.get_mut(kind as usize)?.as_any_mut().downcast_mut::<T>()
    }

    pub fn store(&self, kind: u16) -> &dyn ShapeStore2 {
        self.shapes[kind as usize].as_ref()
    }

    /// Adds a body whose shape is `shape` (already in its store); mass and inertia
    /// come from the shape and the material's density.
    pub fn add_body(&mut self, shape: ShapeRef, material: u16, pos: [f64; 2], rot: f64, vel: [f64; 3]) -> u32 {
        let mp = self.shapes[shape.kind as usize].mass_properties(shape.index, self.materials[material as usize].density);
        self.names.push(None);
        self.origins.push(self.origin);
        self.bodies.push(pos, rot, vel, mp.mass, mp.inertia, mp.area, shape, material)
    }

    /// Makes a body immovable.
    pub fn set_fixed(&mut self, b: u32) {
        self.bodies.set_fixed(b as usize);
    }

    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Position of body b.
    pub fn position(&self, b: u32) -> [f64; 2] {
        self.bodies.pos[b as usize]
    }
}
