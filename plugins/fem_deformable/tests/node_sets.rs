//! A node set's G (the blocks of M̂⁻¹ among a body's contact nodes) is kept while
//! its nodes and the body's M̂⁻¹ stay, and only then (`nodes::fill_set`); a body's
//! factors dropped (on MPI ranks) are made again with the same numbers.
mod common;
use common::*;
use nscdd_fem_deformable::nodes::{fill_nodes, fill_set, NodeSet};

const SCENE: &str = r#"
[time]
step = 1e-3
steps = 1
[[materials]]
name = "soil"
density = 2000.0
[[deformable]]
material = "soil"
young = 1e7
poisson = 0.3
mesh = { rectangle = { origin = [0.0, 0.0], size = [0.4, 0.2], cells = [8, 4] } }
"#;

#[test]
fn g_is_kept_while_the_nodes_and_the_factor_stay() {
    let mut s = scene(SCENE);
    let body = &mut s.fe.bodies[0];
    let nodes = [0u32, 3, 7, 20];
    let mut set = NodeSet::<2>::default();
    fill_set(&mut set, body, &nodes, 1.0);
    let g1 = set.g.clone();
    assert!(g1.iter().any(|&x| x != 0.0));
    // the same nodes and factor: kept (a sentinel shows it was not refilled)
    set.g[0] = 42.0;
    fill_set(&mut set, body, &nodes, 1.0);
    assert_eq!(set.g[0], 42.0);
    // another scale: refilled
    fill_set(&mut set, body, &nodes, 2.0);
    assert_eq!(set.g[0], 2.0 * g1[0]);
    fill_set(&mut set, body, &nodes, 1.0);
    assert_eq!(set.g, g1);
    // another h: M̂ changes, G is filled from the new columns
    assert!(body.factorize(2e-3, 0.5).unwrap());
    fill_set(&mut set, body, &nodes, 1.0);
    let mut fresh = NodeSet::<2>::default();
    fill_set(&mut fresh, body, &nodes, 1.0);
    assert_eq!(set.g, fresh.g);
    assert_ne!(set.g, g1);
    // a body not stepped here: G current for the same nodes, kept aside (reading as
    // 0, not copied into parts) for others
    fill_nodes(&mut set, &nodes);
    assert_eq!(set.g, fresh.g);
    assert!(set.v.iter().all(|v| *v == [0.0; 2]));
    let side = nscdd_fem_deformable::nodes::FeSide::<2>::node(0, 0);
    assert_ne!(set.side_block(&side), [[0.0; 2]; 2]);
    fill_nodes(&mut set, &nodes[..3]);
    assert_eq!(set.side_block(&side), [[0.0; 2]; 2]);
    assert!(set.clone().g.is_empty());
    // and stepped again, its G is that of a fresh fill
    fill_set(&mut set, body, &nodes, 1.0);
    assert_eq!(set.g, fresh.g);
    // some nodes changed: the old nodes' blocks copied, the new ones' read, the
    // same numbers as a fresh fill
    for next in [&[0u32, 7, 9, 20, 44][..], &[1, 2], &[0, 1, 2, 7, 9, 20, 44], &[]] {
        fill_set(&mut set, body, next, 1.0);
        let mut f = NodeSet::<2>::default();
        fill_set(&mut f, body, next, 1.0);
        assert_eq!(set.g, f.g, "{next:?}");
        assert_eq!(set.nodes, next);
    }
    fill_set(&mut set, body, &nodes, 1.0);
    assert_eq!(set.g, fresh.g);
    // columns dropped (a body a rank no longer steps) are solved again, the same
    // numbers, when the nodes change
    let more = [0u32, 3, 7, 20, 31];
    let mut before = NodeSet::<2>::default();
    fill_set(&mut before, body, &more, 1.0);
    body.release_columns();
    assert_eq!(body.cached_columns(), 0);
    fill_set(&mut set, body, &more, 1.0);
    assert_eq!(set.g, before.g);
    assert_eq!(body.cached_columns(), more.len());
    // and with its G dropped too
    body.release_columns();
    set.release_g();
    assert_eq!(set.side_block(&side), [[0.0; 2]; 2]);
    fill_set(&mut set, body, &nodes, 1.0);
    assert_eq!(set.g, fresh.g);
}

/// A body whose factors a rank dropped ([`FeBody::release_factor`], a body it does
/// not step) factors M̂ again when stepped: the same columns, G and free velocity,
/// bit for bit.
#[test]
fn a_released_factor_is_made_again_with_the_same_numbers() {
    let mut s = scene(SCENE);
    let body = &mut s.fe.bodies[0];
    let nodes = [0u32, 3, 7, 20, 31];
    let (h, theta) = (1e-3, 0.5);
    body.u.iter_mut().enumerate().for_each(|(i, u)| *u = 1e-4 * (i as f64).sin());
    body.v.iter_mut().enumerate().for_each(|(i, v)| *v = 1e-2 * (i as f64).cos());
    let (u0, v0) = (body.u.clone(), body.v.clone());
    let mut before = NodeSet::<2>::default();
    fill_set(&mut before, body, &nodes, 1.0);
    body.free_velocity(h, theta);
    let v_free = body.v_free.clone();
    body.release_factor();
    assert!(!body.is_factored());
    assert_eq!(body.cached_columns(), 0);
    // what an unstepped body still does: its energies (M and K are kept)
    let e = body.energies(&body.u, &body.v);
    assert!(e[0] > 0.0 && e[1] > 0.0);
    assert!(body.factorize(h, theta).unwrap());
    assert!(body.is_factored());
    let mut after = NodeSet::<2>::default();
    fill_set(&mut after, body, &nodes, 1.0);
    assert_eq!(after.g, before.g);
    (body.u, body.v) = (u0, v0);
    body.free_velocity(h, theta);
    assert_eq!(body.v_free, v_free);
    // the same (h, θ): no factorization
    assert!(!body.factorize(h, theta).unwrap());
}

/// Loaded for a run on MPI ranks (`FamilyContext::ranks`), a large body
/// (`stepped::RELEASE_MIN_BYTES`) is assembled and factored only by the rank
/// checking it (⌊i P / N⌋); any other rank assembles and factors it, the same
/// numbers, when it steps it. So is a small body (kept once made); loaded for one
/// process, every body is.
#[test]
fn large_bodies_loaded_on_ranks_hold_no_matrices() {
    // 131 × 101 nodes: M, K and factors of about 17 MB
    let text = SCENE.replace("size = [0.4, 0.2], cells = [8, 4]", "size = [1.3, 1.0], cells = [130, 100]");
    let s = scene(&text);
    let t: toml::Table = toml::from_str(&text).unwrap();
    let entries: Vec<toml::Table> = t["deformable"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_table().unwrap().clone())
        .collect();
    let small: Vec<toml::Table> = toml::from_str::<toml::Table>(SCENE).unwrap()["deformable"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_table().unwrap().clone())
        .collect();
    let load = |entries: &[toml::Table], ranks| {
        let cx = nscdd::family::FamilyContext {
            world: &s.world,
            dir: std::path::Path::new("."),
            max_memory: None,
            ranks,
        };
        nscdd_fem_deformable::scene::bodies_from(entries, &cx).unwrap().remove(0)
    };
    let (small_on_0, small_on_1) = (load(&small, Some((0, 2))), load(&small, Some((1, 2))));
    assert!(small_on_0.is_factored() && !nscdd_fem_deformable::scene::is_large(&small_on_0));
    assert!(!small_on_1.is_factored() && !small_on_1.has_matrices());
    let mut one = load(&entries, None);
    assert!(one.is_factored() && one.has_matrices() && one.is_releasable());
    let nodes = [0u32, 3, 7, 20, 31];
    let mut g_one = NodeSet::<2>::default();
    fill_set(&mut g_one, &mut one, &nodes, 1.0);
    let (h, theta) = (s.world.time.h, s.world.time.theta);
    // rank 0 of 2 checks body 0 (the same numbers as one process); rank 1 does not
    let mut b = load(&entries, Some((0, 2)));
    assert!(b.is_factored() && b.has_matrices() && b.f_ext == one.f_ext);
    b.release_matrices();
    for mut b in [b, load(&entries, Some((1, 2)))] {
        assert!(!b.is_factored() && !b.has_matrices() && b.f_ext.is_empty());
        // the saved energies, assembled aside: the same numbers
        assert_eq!(b.energies_now().unwrap(), one.energies_now().unwrap());
        assert!(b.ensure_matrices().unwrap());
        assert!(b.factorize(h, theta).unwrap());
        assert_eq!(b.f_ext, one.f_ext);
        let mut g = NodeSet::<2>::default();
        fill_set(&mut g, &mut b, &nodes, 1.0);
        assert_eq!(g.g, g_one.g);
        b.free_velocity(h, theta);
        one.free_velocity(h, theta);
        assert_eq!(b.v_free, one.v_free);
        // dropped again (a body idle on the rank): all of it
        b.release_matrices();
        assert!(!b.is_factored() && !b.has_matrices() && b.cached_columns() == 0);
    }
}
