//! The 2D continuum tests' driver: a scene stepped with its NSCDD stage.
use nscdd::dd::{DdConfig, NscddOf, Rigid2};
use nscdd::family::SceneFamily;
use nscdd::scene::Scene;
use nscdd_fem_deformable::continuum::Continuum2;

/// A scene and its NSCDD stage (one subdomain without a decomposition).
pub struct Run {
    pub s: Scene<nscdd::dim::D2>,
    pub dd: Option<NscddOf<Rigid2>>,
}

impl Run {
    pub fn new(text: &str) -> Run {
        let mut s = Scene::<nscdd::dim::D2>::load_str(text, "test.toml", &super::registry()).unwrap_or_else(|e| panic!("{e}"));
        let one = DdConfig::default();
        let cfg = s
            .decomposition
            .clone()
            .or(nscdd::family::needs_nscdd(false, &mut s.families).then_some(one));
        let dd = cfg.map(|c| c.solver_of());
        Run { s, dd }
    }
    pub fn step(&mut self) -> nscdd::engine::StepReport {
        let mut fams: Vec<&mut dyn SceneFamily<nscdd::dim::D2>> = self.s.families.iter_mut().map(|f| &mut **f).collect();
        nscdd::family::step(&mut self.s.world, &mut fams, self.dd.as_mut()).unwrap().0
    }
    pub fn cont(&self) -> &Continuum2 {
        self.s.families[0].as_any().downcast_ref::<Continuum2>().unwrap()
    }
}
