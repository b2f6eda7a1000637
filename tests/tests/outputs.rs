//! The outputs of a run: history.csv columns and rows, final.json fields, VTK files
//! that read back (vtkio) with one point per body and one line per contact, and the
//! .pvd series listing every frame.

use vtkio::model::{DataSet, Piece, VertexNumbers};

const SCENE: &str = r#"
[time]
step = 1e-3
steps = 20
[output]
every = 5
[[materials]]
name = "m"
density = 1000.0
[[laws]]
materials = ["m", "m"]
friction = 0.3
[[bodies]]
name = "floor"
shape = "wall"
material = "m"
position = [0.1, -0.005]
length = 0.4
thickness = 0.01
fixed = true
[[generate]]
kind = "square_lattice"
material = "m"
nx = 5
ny = 3
radius = 0.01
origin = [0.01, 0.01]
"#;

fn points_and_cells(path: &std::path::Path) -> (usize, usize, usize) {
    let vtk = vtkio::Vtk::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let DataSet::PolyData { pieces, .. } = vtk.data else {
        panic!("not polydata")
    };
    let Piece::Inline(p) = &pieces[0] else { panic!("not inline") };
    let n = |v: &Option<VertexNumbers>| v.as_ref().map(|v| v.num_cells()).unwrap_or(0);
    (p.num_points(), n(&p.verts), n(&p.lines))
}

#[test]
fn run_writes_history_final_and_vtk() {
    let reg = nscdd_rigid_disks::registry();
    let mut s = nscdd::scene::load_str(SCENE, "outputs.toml", &reg).unwrap();
    let dir = std::env::temp_dir().join(format!("nscdd-outputs-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let sum = nscdd::run::run(&mut s, &reg, &dir, |_, _| {}).unwrap();
    assert_eq!(sum.steps, 20);

    let hist = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let lines: Vec<&str> = hist.lines().collect();
    assert_eq!(lines.len(), 21, "a header and one row per step");
    let head: Vec<&str> = lines[0].split(',').collect();
    for c in [
        "step",
        "time",
        "bodies",
        "contacts",
        "sweeps",
        "converged",
        "QuadDV",
        "MaxmDVR",
        "MeanDVoR",
        "residual",
        "kinetic_energy",
        "potential_energy",
        "floor_fy",
        "t_nlgs",
    ] {
        assert!(head.contains(&c), "column {c}");
    }
    for l in &lines[1..] {
        assert_eq!(l.split(',').count(), head.len());
    }
    // the floor carries the weight of the 15 disks at the end
    let last: Vec<f64> = lines[20].split(',').map(|x| x.parse().unwrap()).collect();
    let fy = last[head.iter().position(|c| *c == "floor_fy").unwrap()];
    let weight = 15.0 * 1000.0 * std::f64::consts::PI * 1e-4 * 9.81;
    assert!((fy + weight).abs() < 1e-3 * weight, "floor force {fy} vs weight {weight}");

    let fin: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("final.json")).unwrap()).unwrap();
    assert_eq!(fin["step"], 20);
    let bodies = fin["bodies"].as_array().unwrap();
    assert_eq!(bodies.len(), 16);
    for key in ["id", "kind", "material", "position", "rotation", "velocity", "fixed", "shape"] {
        assert!(bodies[1].get(key).is_some(), "body field {key}");
    }
    assert_eq!(bodies[0]["name"], "floor");
    assert_eq!(bodies[1]["kind"], "disk");
    let contacts = fin["contacts"].as_array().unwrap();
    assert!(contacts.len() >= 5 + 10, "floor and lattice contacts");
    assert_eq!(fin["dimension"], 2);
    for key in ["bodies", "feature", "point", "normal", "r", "impulse", "gap"] {
        assert!(contacts[0].get(key).is_some(), "contact field {key}");
    }

    // frames 0 (initial), steps 5, 10, 15, 20
    let pvd = std::fs::read_to_string(dir.join("bodies.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 5);
    let (np, nv, _) = points_and_cells(&dir.join("vtk/bodies_000004.vtp"));
    assert_eq!((np, nv), (16, 16));
    let (_, _, nl) = points_and_cells(&dir.join("vtk/contacts_000004.vtp"));
    assert_eq!(nl, contacts.len());
    let _ = std::fs::remove_dir_all(&dir);
}
