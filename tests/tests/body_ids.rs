//! Compact arrays, first step (docs/SCALING.md, "Bodies owned per rank", item 5):
//! the world's slots and the scene's global ids ([`nscdd::model::BodyIds`]). A
//! world whose bodies carry global ids with gaps (every body held, slot k ↦
//! 2k + [k mod 3 = 0]) steps with NSCDD bitwise as the plain world: positions,
//! velocities, impulses, reactions and the reports, its contact keys the plain ones
//! in global ids. This checks every translation between NSCDD (global ids) and the
//! world (slots) before any process drops a body: with threads, with the rank driver
//! in one process (contacts and bodies held per rank, [`nscdd::dd::Solo`]), in 2D
//! and 3D, with repartitions.

use nscdd::dd::{DdSettings, DdStepReport, NscddOf, Rigid, Scheme, Solo};
use nscdd::dim::Dim;
use nscdd::model::{BodyIds, ContactKey};
use nscdd::scene::Scene;

fn spread_id(k: u32) -> u32 {
    2 * k + u32::from(k % 3 == 0)
}

/// The same scene with gapped global ids.
fn spread<D: Dim>(s: &mut Scene<D>) {
    let n = s.world.bodies.len() as u32;
    s.world.ids = BodyIds::spread((0..n).map(spread_id).collect(), 2 * n + 1).expect("ascending ids");
}

fn bits<T: AsRef<[f64]>>(v: &[T]) -> Vec<Vec<u64>> {
    v.iter().map(|x| x.as_ref().iter().map(|y| y.to_bits()).collect()).collect()
}

/// Steps `a` (plain) and `b` (gapped) `steps` times with the same NSCDD settings
/// (`solo`: the rank driver in one process) and compares them; returns the plain
/// run's reports.
fn compare<D: Dim>(mut a: Scene<D>, mut b: Scene<D>, settings: DdSettings, solo: bool, steps: usize) -> Vec<DdStepReport>
where
    D::Twist: AsRef<[f64]>,
    D::Point: AsRef<[f64]>,
    D::Local: AsRef<[f64]>,
{
    spread(&mut b);
    let make = || {
        let n = NscddOf::<Rigid<D>>::new(settings.clone()).with_repartition_every(4);
        if solo {
            n.with_cluster(Box::new(Solo)).expect("one rank fits the subdomains")
        } else {
            n
        }
    };
    let (mut na, mut nb) = (make(), make());
    let mut reports = Vec::new();
    for k in 0..steps {
        let ra = na.step(&mut a.world).unwrap();
        let rb = nb.step(&mut b.world).unwrap();
        let key = |r: &DdStepReport| (r.stages, r.solve.sweeps, r.solve.converged, r.interface_bodies, r.links, r.contacts);
        assert_eq!(key(&ra), key(&rb), "step {k}");
        assert_eq!(ra.egluing.to_bits(), rb.egluing.to_bits(), "step {k}");
        assert_eq!(ra.solve.residual.to_bits(), rb.solve.residual.to_bits(), "step {k}");
        reports.push(ra);
    }
    let (wa, wb) = (&a.world, &b.world);
    assert_eq!(bits(&wa.bodies.pos), bits(&wb.bodies.pos), "positions");
    assert_eq!(bits(&wa.bodies.vel), bits(&wb.bodies.vel), "velocities");
    assert_eq!(bits(&wa.contacts.r), bits(&wb.contacts.r), "impulses");
    assert_eq!(bits(&wa.reaction), bits(&wb.reaction), "reactions");
    assert_eq!(wa.contacts.bodies, wb.contacts.bodies, "the contacts' slots");
    let global = |k: &ContactKey| ContactKey {
        i: spread_id(k.i),
        j: spread_id(k.j),
        feature: k.feature,
    };
    assert_eq!(wa.contacts.key.iter().map(global).collect::<Vec<_>>(), wb.contacts.key, "keys");
    assert!(!wa.contacts.is_empty(), "the test has contacts");
    // final.json names the bodies and the contacts' bodies by global id
    let json = |w| serde_json::from_str::<serde_json::Value>(&nscdd::output::final_json(w)).expect("final.json");
    let (ja, mut jb) = (json(wa), json(wb));
    for b in jb["bodies"].as_array_mut().expect("bodies") {
        let g = b["id"].as_u64().expect("an id") as u32;
        b["id"] = ((0..).find(|&k| spread_id(k) == g).expect("a spread id")).into();
    }
    for c in jb["contacts"].as_array_mut().expect("contacts") {
        for x in c["bodies"].as_array_mut().expect("the contact's bodies") {
            let g = x.as_u64().expect("an id") as u32;
            *x = ((0..).find(|&k| spread_id(k) == g).expect("a spread id")).into();
        }
    }
    assert_eq!(ja, jb, "final.json, ids mapped back");
    reports
}

const PILE: &str = include_str!("scenes/pile48.toml");

fn pile() -> Scene {
    let reg = nscdd_rigid_disks::registry();
    nscdd::scene::load_str(PILE, "pile.toml", &reg).unwrap_or_else(|e| panic!("{e}"))
}

fn pile_settings(scheme: Scheme) -> DdSettings {
    DdSettings {
        nx: 3,
        ny: 2,
        scheme,
        threads: 2,
        ..Default::default()
    }
}

#[test]
fn gapped_ids_step_as_the_plain_world_with_threads() {
    for scheme in [Scheme::Decentralized, Scheme::Centralized] {
        let reps = compare(pile(), pile(), pile_settings(scheme), false, 20);
        assert!(reps.iter().map(|r| r.interface_bodies).sum::<usize>() > 0, "interface bodies");
    }
}

#[test]
fn gapped_ids_step_as_the_plain_world_on_the_rank_driver() {
    for scheme in [Scheme::Decentralized, Scheme::Centralized] {
        let reps = compare(pile(), pile(), pile_settings(scheme), true, 20);
        assert!(reps.iter().map(|r| r.interface_bodies).sum::<usize>() > 0, "interface bodies");
    }
}

#[test]
fn gapped_ids_step_as_the_plain_world_in_3d() {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/triaxial3d.toml")).expect("the example");
    let reg = nscdd_spheres::registry();
    let load = || nscdd::scene::Scene3::load_str(&text, "triaxial3d.toml", &reg).unwrap_or_else(|e| panic!("{e}"));
    let settings = DdSettings {
        nx: 2,
        ny: 2,
        ..Default::default()
    };
    for solo in [false, true] {
        let reps = compare(load(), load(), settings.clone(), solo, 40);
        assert!(reps.iter().map(|r| r.interface_bodies).sum::<usize>() > 0, "interface bodies");
    }
}

/// Compact arrays: drops the grains `leave` picks (none of them in a contact) with
/// their records, checks the world holds the others only, admits them back, and
/// checks the world is `plain`'s bit for bit, then after `steps` more steps each.
fn leave_and_come_back<D: Dim>(mut plain: Scene<D>, mut w: Scene<D>, leave: impl Fn(usize) -> bool, steps: usize)
where
    D::Twist: AsRef<[f64]>,
    D::Point: AsRef<[f64]>,
    D::Local: AsRef<[f64]>,
{
    let wd = &mut w.world;
    let n = wd.bodies.len();
    let in_contact: Vec<bool> = (0..n).map(|k| wd.contacts.bodies.iter().any(|p| p.contains(&(k as u32)))).collect();
    let gone: Vec<usize> = (0..n).filter(|&k| wd.is_grain(k) && !in_contact[k] && leave(k)).collect();
    assert!(!gone.is_empty(), "the test drops bodies");
    let mut rec = vec![Vec::new(); gone.len()];
    for (r, &k) in rec.iter_mut().zip(&gone) {
        wd.body_record(k, r);
    }
    let keep: Vec<u32> = (0..n as u32).filter(|k| !gone.contains(&(*k as usize))).collect();
    wd.hold(&keep);
    assert_eq!(wd.bodies.len(), keep.len());
    assert_eq!(wd.ids.held(), Some(&keep[..]));
    // the whole scene's sums kept
    assert_eq!(wd.grain_sums().0, plain.world.grain_sums().0);
    let entering: Vec<(u32, &[f64])> = gone.iter().zip(&rec).map(|(&k, r)| (k as u32, &r[..])).collect();
    wd.admit(&entering);
    assert_eq!(wd.bodies.len(), n);
    for round in 0..2 {
        let (a, b) = (&plain.world, &w.world);
        assert_eq!(bits(&a.bodies.pos), bits(&b.bodies.pos), "positions, round {round}");
        assert_eq!(bits(&a.bodies.vel), bits(&b.bodies.vel), "velocities, round {round}");
        assert_eq!(a.bodies.mass, b.bodies.mass);
        assert_eq!(format!("{:?}", a.bodies.inv_mass), format!("{:?}", b.bodies.inv_mass));
        assert_eq!(format!("{:?}", a.bodies.rot), format!("{:?}", b.bodies.rot));
        assert_eq!(
            (&a.bodies.shape, &a.bodies.material, &a.bodies.free),
            (&b.bodies.shape, &b.bodies.material, &b.bodies.free)
        );
        assert_eq!((&a.names, &a.fixed), (&b.names, &b.fixed));
        assert_eq!(bits(&a.contacts.r), bits(&b.contacts.r), "impulses, round {round}");
        assert_eq!(a.contacts.bodies, b.contacts.bodies);
        assert_eq!(
            nscdd::output::final_json(a),
            nscdd::output::final_json(b),
            "final.json, round {round}"
        );
        for _ in 0..steps {
            plain.world.step().unwrap();
            w.world.step().unwrap();
        }
    }
}

#[test]
fn a_body_dropped_and_admitted_back_steps_as_before() {
    // before the first step, every other grain
    leave_and_come_back(pile(), pile(), |k| k % 2 == 1, 30);
    // in 3D mid-run, the grains without contacts (walls driven, named: kept)
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/scenes/triaxial3d.toml")).expect("the example");
    let reg = nscdd_spheres::registry();
    let load = || {
        let mut s = nscdd::scene::Scene3::load_str(&text, "triaxial3d.toml", &reg).unwrap_or_else(|e| panic!("{e}"));
        for _ in 0..5 {
            s.world.step().unwrap();
        }
        s
    };
    leave_and_come_back(load(), load(), |_| true, 10);
}
