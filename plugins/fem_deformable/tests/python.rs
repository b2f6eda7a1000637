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

#[test]
fn box_boundary_faces_point_outwards() {
    let raw = python::cuboid([0.0; 3], [1.0; 3], [2, 2, 2]).unwrap();
    let m = nscdd_fem_deformable::mesh::Mesh::new(raw).unwrap();
    // 6 sides × 4 squares × 2 triangles
    assert_eq!(m.n_facets(), 48);
    for s in 0..m.n_facets() {
        let f = m.facet(s);
        let p = |k: u32| [m.x0[3 * k as usize], m.x0[3 * k as usize + 1], m.x0[3 * k as usize + 2]];
        let (a, b, c) = (p(f[0]), p(f[1]), p(f[2]));
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let g = [
            (a[0] + b[0] + c[0]) / 3.0 - 0.5,
            (a[1] + b[1] + c[1]) / 3.0 - 0.5,
            (a[2] + b[2] + c[2]) / 3.0 - 0.5,
        ];
        assert!(n[0] * g[0] + n[1] * g[1] + n[2] * g[2] > 0.0, "face {s} points inwards");
    }
}
