//! A fresh scene loaded on MPI ranks in part (issue 20): no rank ever holds every
//! body of the scene.
//!
//! 1. **Survey** ([`survey_any`]): every rank reads the file and runs its bodies and
//!    generators holding none of them ([`crate::scene::builder::Part`]); it keeps
//!    of every body only what the whole-scene checks and the first grid read (≈ 60
//!    B a body: centre, mass, ρ², volume, shape, material, whether it moves), and
//!    runs those checks (laws and detectors, masses, the alert distance), so that
//!    every rank refuses the same bad scene with the same message.
//! 2. The command line's decomposition flags apply ([`crate::dd::DdConfig`]).
//! 3. **Part** ([`load_on`]): the provisional grid over the movable bodies'
//!    centres and its cells' ranks ([`crate::dd::first_part::provisional`], the
//!    first step's own rule), then the file again, each rank holding only the
//!    bodies whose box, grown by the alert distance, meets its cells (the halo's
//!    own test) and those every rank steps (immovable, driven, named, unbounded):
//!    what the first step keeps of a whole world, so results stay bitwise those of
//!    one process. The overlap check runs on the bodies a rank holds (an
//!    overlapping pair is held by the rank of a cell holding a point of both).
//!
//! 4. **A restart** ([`restart_on`]) of the state of the same decomposition: a first
//!    pass over the state marks the bodies of the rank's first step after the
//!    restart (its halo of the saved grid at the saved poses, those every rank
//!    steps, those of the contacts it keeps: [`super::restart_scan`]); the rank
//!    builds only those, and the restart writes their saved state and its contacts.
//!
//! 5. **Body families** ([`crate::family::FamilyKind::load_boxes`]): the survey asks
//!    each family, before any body is built, for boxes holding every world body its
//!    load reads and its first step may name (a continuum region's mesh box, a
//!    deformable body's reach); every rank also holds the bodies near them, and the
//!    families are loaded against the rank's part; restarted, the boxes also hold
//!    the families' first step at the saved state (the state's `families` read
//!    alone), and the bodies near them are chosen at their saved poses as well as
//!    at the scene's. A family without such boxes loads the scene whole, as before
//!    (each rank keeps its part before the first step). Decomposed by model, as by
//!    geometry: a family's subdomain of a cell goes with the cell to its rank.
//!
//! Scenes with no decomposition, and restarts from a state of another
//! decomposition, are loaded whole, as before. The ranks agree on the survey's
//! digest of every body and of the families' boxes (and, restarted, on every saved
//! body's and contact's).

use super::builder::Part;
use super::schema::{BodySpec, SceneDim, SceneFile};
use super::{AnyScene, Ctx, Scene, Scene3, Sections};
use crate::dim::{D2, D3};
use crate::error::InputError;
use crate::registry::Registry;
use std::hash::Hasher;

/// What the survey of a scene gives every rank.
#[derive(Clone, Debug, Default)]
pub struct Survey {
    /// The scene's text and file name (read again for the part).
    text: String,
    file: String,
    /// The movable bodies' centres, in id order (the provisional grid's points).
    centres: Vec<[f64; 3]>,
    /// The bodies every rank holds (ascending).
    everywhere: Vec<u32>,
    /// Every body's shape, by global id (a restart's boxes at the saved poses).
    shapes: Vec<crate::model::ShapeRef>,
    /// The body families' sections and load boxes
    /// ([`crate::family::FamilyKind::load_boxes`]).
    sections: Sections,
    boxes: Vec<[[f64; 3]; 2]>,
    /// The scene has body families (then loaded against each rank's part).
    pub families: bool,
    /// The movable bodies (the decomposition flags' check).
    pub movable: usize,
    /// A digest of every body's columns and of the bodies every rank holds.
    pub digest: u64,
}

/// The survey of the scene at `path` (any dimension): a scene whose world holds no
/// body, its [`Scene::survey`] set; `None` for a scene with a body family that
/// gives no load boxes (loaded whole on every rank; each rank then keeps its part,
/// [`crate::dd::NscddOf::start_ranks`]).
pub fn survey_any(path: &std::path::Path, registry: &Registry) -> Result<Option<AnyScene>, InputError> {
    let (text, file) = super::read_file(path)?;
    Ok(match super::dimension_of(&text) {
        Some(3) => survey::<D3>(&text, &file, registry)?.map(AnyScene::D3),
        _ => survey::<D2>(&text, &file, registry)?.map(AnyScene::D2),
    })
}

/// Loads `text`'s rigid bodies with `part` (every body's columns kept, those it
/// accepts held), and its families' sections (checked, not loaded).
fn load_with<D: SceneDim>(text: &str, file: &str, registry: &Registry, part: Part) -> Result<(Scene<D>, Part, Sections), InputError> {
    let mut sf: SceneFile<BodySpec<D>> = super::parse(text, file)?;
    let cx = Ctx {
        text,
        file,
        families: !sf.sections.is_empty(),
        ranks: None,
    };
    super::dimension_is::<D>(&cx, &sf)?;
    let sections = std::mem::take(&mut sf.sections);
    super::check_sections::<D>(&cx, &sections, registry)?;
    let (scene, part) = super::load::load_parsed_part(&cx, sf, registry, Some(part))?;
    Ok((scene, part.expect("the part given"), sections))
}

fn survey<D: SceneDim>(text: &str, file: &str, registry: &Registry) -> Result<Option<Scene<D>>, InputError> {
    let (mut scene, mut p, sections) = load_with::<D>(text, file, registry, Part::new(Box::new(|_, _| false), 0.0))?;
    let cx = Ctx {
        text,
        file,
        families: !sections.is_empty(),
        ranks: None,
    };
    let Some(boxes) = super::family_boxes(&cx, &scene, &sections, registry, None)? else {
        return Ok(None);
    };
    let driven = &p.driven;
    let mut everywhere: Vec<u32> = (0..p.centre.len() as u32).filter(|&g| !p.movable[g as usize]).collect();
    everywhere.extend(driven.iter().chain(&p.unbounded).copied().chain(p.named.iter().map(|x| x.0)));
    everywhere.sort_unstable();
    everywhere.dedup();
    // (orientations, velocities, names, drives and box walls: hashed as read)
    let mut h = p.hash.clone();
    for g in 0..p.centre.len() {
        let (s, c) = (p.shape[g], &p.centre[g]);
        c.iter()
            .chain([&p.mass[g], &p.rho2[g], &p.volume[g]])
            .for_each(|x| h.write_u64(x.to_bits()));
        h.write_u64(u64::from(s.kind) << 48 | u64::from(s.index) << 16 | u64::from(p.material[g]));
        h.write_u8(u8::from(p.movable[g]));
    }
    everywhere.iter().for_each(|&g| h.write_u32(g));
    boxes.iter().flatten().flatten().for_each(|x| h.write_u64(x.to_bits()));
    // the movable bodies' centres, in place (not a second N-sized list)
    let mut centres = std::mem::take(&mut p.centre);
    let mut g = 0;
    centres.retain(|_| {
        g += 1;
        p.movable[g - 1]
    });
    scene.survey = Some(Survey {
        text: text.to_string(),
        file: file.to_string(),
        movable: centres.len(),
        centres,
        everywhere,
        shapes: std::mem::take(&mut p.shape),
        boxes,
        sections,
        families: cx.families,
        digest: h.finish(),
    });
    Ok(Some(scene))
}

/// After [`survey_any`] and the decomposition flags: loads the scene as rank `me`
/// of `ranks`, holding its part when the first step will run per rank (a
/// decomposition by geometry; [`Scene::part`] then hands the provisional grid to
/// the solver), or whole (the scene as [`super::load_any`] loads it). The flags'
/// decomposition is kept. Returns whether the scene is held in part.
pub fn load_on<D: SceneDim>(s: &mut Scene<D>, registry: &Registry, (ranks, me): (u32, u32)) -> Result<bool, InputError> {
    let Some(sv) = s.survey.take() else { return Ok(false) };
    let decomposition = s.decomposition.take();
    // (a grid of fewer cells than ranks is refused when the run starts)
    // (by model, each family's subdomain of a cell goes with the cell)
    let first = decomposition
        .as_ref()
        .filter(|c| ranks > 1 && c.dd.nx as u64 * c.dd.ny as u64 * c.dd.nz as u64 >= u64::from(ranks))
        .and_then(|c| crate::dd::first_part::provisional(&sv.centres, [c.dd.nx, c.dd.ny, c.dd.nz], ranks));
    let Some(first) = first else {
        load_whole(s, registry, &sv, decomposition, (me, ranks))?;
        return Ok(false);
    };
    // (a margin on the alert distance: a body kept in excess leaves at the first step)
    let alert = s.world.alert * 1.01;
    let halo = crate::dd::first_part::Halo::new(&first, me, D::N, alert);
    let near = crate::dd::first_part::Halo::around(sv.boxes.clone(), D::N, alert);
    let everywhere = sv.everywhere.clone();
    let keep = move |g: u32, b: &[[f64; 3]; 2]| everywhere.binary_search(&g).is_ok() || halo.meets(b) || near.meets(b);
    load_part(s, registry, &sv, Part::new(Box::new(keep), 1.0 / f64::from(ranks)), (me, ranks))?;
    check_family_part(s, &sv.boxes, &sv.file)?;
    s.decomposition = decomposition;
    s.part = Some(first);
    s.survey = Some(Survey {
        file: sv.file,
        movable: sv.movable,
        families: sv.families,
        digest: sv.digest,
        ..Default::default()
    });
    Ok(true)
}

/// The surveyed scene loaded as `part` keeps it (rank `on` = (this rank, ranks)'s
/// part), its families loaded against that part.
fn load_part<D: SceneDim>(s: &mut Scene<D>, registry: &Registry, sv: &Survey, part: Part, on: (u32, u32)) -> Result<(), InputError> {
    let (scene, _, sections) = load_with::<D>(&sv.text, &sv.file, registry, part)?;
    *s = scene;
    let cx = Ctx {
        text: &sv.text,
        file: &sv.file,
        families: sv.families,
        ranks: (on.1 > 1).then_some(on),
    };
    s.add_families(&cx, sections, registry)
}

/// The surveyed scene loaded whole (as [`super::load_any`] loads it), with the
/// flags' `decomposition`, for rank `on` = (this rank, ranks).
fn load_whole<D: SceneDim>(
    s: &mut Scene<D>,
    registry: &Registry,
    sv: &Survey,
    decomposition: Option<crate::dd::DdConfig>,
    on: (u32, u32),
) -> Result<(), InputError> {
    *s = Scene::<D>::load_str_on(&sv.text, &sv.file, registry, (on.1 > 1).then_some(on))?;
    s.decomposition = decomposition;
    Ok(())
}

/// [`load_on`] for a run restarted from the state at `path`, then the restart
/// ([`super::restart_scene_on`]; returns what it returns). When the state's
/// contacts are read in part (the state of the same decomposition, by geometry or
/// by model), a
/// surveyed scene is loaded in part too: a first pass over the state marks the
/// bodies of the rank's first step ([`super::restart_scan`]: its halo of the
/// saved grid at the saved poses, those every rank steps, those of its kept
/// contacts), the rank builds only those and the bodies near its body families'
/// boxes (their load's, and their first step's at the saved state:
/// [`crate::family::FamilyKind::load_boxes`] given the state's `families`), the
/// families load against that part, and the restart writes the saved state of its
/// bodies and the families'. The ranks then agree on the survey's digest, every
/// saved body's and every contact's. Otherwise the scene is loaded whole, as
/// before. (The scene's own overlap check, of the initial positions the state
/// replaces, runs on the bodies each rank holds, chosen at the saved positions: an
/// overlap of the initial positions may go unreported, where one process refuses
/// it.)
pub fn restart_on<D: SceneDim>(
    s: &mut Scene<D>,
    registry: &Registry,
    (ranks, me): (u32, u32),
    path: &std::path::Path,
) -> Result<Option<u64>, InputError> {
    let on = (ranks > 1).then_some((ranks, me));
    let Some(sv) = s.survey.take() else {
        return super::restart_scene_on(s, path, on);
    };
    let mut rp = super::restart::rank_part_of(path, s, on);
    // (by model, or from another decomposition's state: whole; the rank's part
    // is then kept before the first step)
    let boxes = match rp.is_some() && sv.families {
        true => saved_boxes(s, registry, &sv, path)?,
        false => Some(sv.boxes.clone()),
    };
    // (a margin on the alert distance: a body kept in excess leaves at the first step)
    let near = |b: &[[[f64; 3]; 2]]| crate::dd::first_part::Halo::around(b.to_vec(), D::N, s.world.alert * 1.01);
    let scanned = rp.as_mut().zip(boxes.as_ref()).and_then(|(rp, boxes)| {
        let halo = rp.halo(D::N, s.world.alert * 1.01);
        // (the families' first step reads the bodies near their boxes at the saved
        // positions; their load, at the scene's: both kept)
        let near = near(boxes);
        let scene = super::restart_scan::ScanInput {
            shapes: &sv.shapes,
            stores: &s.world.shapes,
            everywhere: &sv.everywhere,
            halo: &halo,
            near: &near,
        };
        super::restart_scan::scan::<D>(path, &scene, rp)
    });
    let decomposition = s.decomposition.take();
    let (Some(scanned), Some(boxes)) = (scanned, boxes) else {
        load_whole(s, registry, &sv, decomposition, (me, ranks))?;
        // (a whole scene with families reads every contact, as before)
        return match sv.families {
            true => super::restart_scene_on(s, path, on),
            false => super::restart::restart_scene_with(s, path, rp),
        };
    };
    let keep = scanned.keep;
    let near = near(&boxes);
    let keep = move |g: u32, b: &[[f64; 3]; 2]| keep[g as usize] || near.meets(b);
    load_part(s, registry, &sv, Part::new(Box::new(keep), 1.0 / f64::from(ranks)), (me, ranks))?;
    s.decomposition = decomposition;
    let contacts = super::restart::restart_scene_with(s, path, rp)?;
    check_family_part(s, &boxes, &sv.file)?;
    let mut h = std::collections::hash_map::DefaultHasher::new();
    let w = &s.world;
    let state = [sv.digest, scanned.digest, contacts.unwrap_or(0), w.step, w.t.to_bits()];
    state.iter().chain(&w.box_h0.map(f64::to_bits)).for_each(|&x| h.write_u64(x));
    s.survey = Some(Survey {
        file: sv.file,
        movable: sv.movable,
        families: sv.families,
        digest: h.finish(),
        ..Default::default()
    });
    Ok(contacts)
}

/// The families' boxes of a restart in part: their load's (the survey's) and their
/// first step's at the saved state (the state's `families` given to
/// [`crate::family::FamilyKind::load_boxes`]); `None` when the state has no
/// readable `families` or a family gives no boxes (the restart is then whole, and
/// reports what is wrong).
fn saved_boxes<D: SceneDim>(
    s: &Scene<D>,
    registry: &Registry,
    sv: &Survey,
    path: &std::path::Path,
) -> Result<Option<Vec<[[f64; 3]; 2]>>, InputError> {
    let Some(saved) = super::restart::families_of(path) else {
        return Ok(None);
    };
    let cx = Ctx {
        text: &sv.text,
        file: &sv.file,
        families: true,
        ranks: None,
    };
    let Some(mut boxes) = super::family_boxes(&cx, s, &sv.sections, registry, Some(&saved))? else {
        return Ok(None);
    };
    boxes.extend_from_slice(&sv.boxes);
    Ok(Some(boxes))
}

/// Once a rank's families are loaded against its part (and restarted): every world
/// body they name is held, and their first reach lies within their load `boxes`.
/// Otherwise a family's [`crate::family::FamilyKind::load_boxes`] are wrong (its
/// plugin's error), reported here rather than as a body missing at a later step.
fn check_family_part<D: SceneDim>(s: &Scene<D>, boxes: &[[[f64; 3]; 2]], file: &str) -> Result<(), InputError> {
    let Some(t) = crate::family::touched(&s.world, &s.families) else {
        return Ok(());
    };
    let key = s.families.iter().map(|f| f.section()).collect::<Vec<_>>().join(", ");
    let why = "the body families' load boxes (`FamilyKind::load_boxes`) do not hold it, so the scene cannot load in part on MPI ranks; this is the family plugin's error";
    let err = |what: String| InputError {
        file: file.to_string(),
        line: None,
        key: key.clone(),
        message: format!("{what}: {why}"),
    };
    if let Some(g) = t.ids.iter().find(|&&g| s.world.ids.slot(g).is_none()) {
        return Err(err(format!("a family names world body {g}, which this rank did not build")));
    }
    if let Some(b) = t.reach.iter().find(|b| !covered(b, boxes, D::N)) {
        return Err(err(format!("a family's first reach {b:?} lies outside its load boxes")));
    }
    Ok(())
}

/// Whether the box `b` lies inside one of `boxes` (the first `n` coordinates).
fn covered(b: &[[f64; 3]; 2], boxes: &[[[f64; 3]; 2]], n: usize) -> bool {
    boxes.iter().any(|c| (0..n).all(|k| c[0][k] <= b[0][k] && b[1][k] <= c[1][k]))
}

/// [`load_on`] for a scene of either dimension.
pub fn load_any_on(s: &mut AnyScene, registry: &Registry, on: (u32, u32)) -> Result<bool, InputError> {
    match s {
        AnyScene::D2(x) => load_on::<D2>(x, registry, on),
        AnyScene::D3(x) => load_on::<D3>(x as &mut Scene3, registry, on),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_reach_box_is_covered_by_a_load_box_that_holds_it() {
        let load = [[[0.0, 0.0, 0.0], [1.0, 1.0, 0.0]], [[2.0, 0.0, 0.0], [3.0, 1.0, 0.0]]];
        let inside = [[0.1, 0.2, 0.0], [0.9, 1.0, 0.0]];
        let across = [[0.5, 0.2, 0.0], [2.5, 0.8, 0.0]];
        let below = [[2.1, -0.1, 0.0], [2.9, 0.5, 0.0]];
        assert!(super::covered(&inside, &load, 2));
        assert!(!super::covered(&across, &load, 2), "two boxes together do not hold it");
        assert!(!super::covered(&below, &load, 2));
        // (2D: z is not compared)
        assert!(super::covered(&[[0.1, 0.2, 5.0], [0.9, 1.0, 6.0]], &load, 2));
    }
}
