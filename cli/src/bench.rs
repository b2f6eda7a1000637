use nscdd::registry::Registry;
pub fn nlgs(_r: &Registry, _n: usize, _k: usize) {}
pub fn deposit(_r: &Registry, _n: usize, _k: usize) {}
