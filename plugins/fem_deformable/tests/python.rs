use nscdd_fem_deformable::python;

#[test]
fn scikit_fem_assembles_a_rectangle() {
    let mesh = python::rectangle([0.0, 0.0], [1.0, 2.0], [2, 2]).unwrap();
    assert_eq!(mesh.points.len(), 18);
    let a = python::assemble(&mesh, 1e6, 0.3, 1000.0, false).unwrap();
    // total mass of each component: ρ × area
    let total: f64 = a.m.data.iter().sum();
    assert!((total - 2.0 * 2000.0).abs() < 1e-6, "{total}");
}
