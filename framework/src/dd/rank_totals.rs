//! `ranks.json`: every rank's exchange, time and memory totals at the end of a
//! multi-process run.

use super::ranks::RankState;

/// Every rank's totals, gathered on every rank (collective), as a JSON document:
/// per rank its gluing messages and values sent, gluing rounds, peers (the ranks it
/// sent gluing messages to), reduction messages and values, and seconds; its CPU
/// seconds since the run started, those spent in communication (`wait_cpu_seconds`,
/// the main thread's) and the rest (`compute_cpu_seconds`): a rank's compute
/// measured apart from its waits even when ranks share cores; its peak resident
/// memory (`peak_rss_mib`, at the end of the run: `final.json` written); the other
/// ranks' subdomains' bodies it held, summed over the steps (`shell_bodies`), and
/// the steps whose shells were limited to the bodies near it
/// (`limited_shell_steps`, [`super::shells`]); the bodies its world held, summed
/// over the steps (`bodies_held`, [`crate::world::held`]), and the most in one step
/// (`bodies_held_max`); the restart's contacts its world loaded (`restart_contacts`:
/// the state read in part, [`super::RestartPart`], gives each contact to one rank);
/// the bodies its world held before the first step of a fresh run or after a
/// restart (`loaded_bodies`: a scene loaded in part, [`crate::scene::part`], gives
/// each rank its halo); the attached families' bodies it stepped and their bodies,
/// summed over the steps stepped in part (`family_bodies_stepped`,
/// `family_bodies`, [`super::Attached::solved_on`]), and of those the bodies whose
/// data only their stepping ranks need it held (`family_bodies_built`, a
/// deformable body's M, K and factors: [`super::Attached::built_bodies`]); the
/// families' contacts it held, summed over the steps (`family_contacts`: each
/// rank its own with contacts held per rank, [`super::Attached::keep_own`]), and
/// those its families' detection found (`family_detected`: between repartitions
/// a rank's own, [`super::Attached::after_free_velocity_own`]), and the
/// families' bodies whose boundary it held current after each step
/// (`family_bodies_near`: with detection per rank the bodies near its cells,
/// [`super::Attached::near_bodies`]).
pub fn totals_json(st: &mut RankState) -> String {
    const H: usize = 29;
    let p = st.cluster.size() as usize;
    let t = &st.totals;
    let (wait_wall, wait_cpu) = st.cluster.waited();
    let (wait_wall, wait_cpu) = (wait_wall - st.wait_start.0, wait_cpu - st.wait_start.1);
    let cpu = super::cluster::cpu_seconds(false) - st.cpu_start;
    let mut mine = vec![
        cpu,
        wait_cpu,
        wait_wall,
        cpu - wait_cpu,
        t.steps as f64,
        t.sent.messages as f64,
        t.sent.values as f64,
        t.rounds as f64,
        t.exchange_seconds,
        t.reduce_seconds,
        t.solve_seconds,
        t.reduce.messages as f64,
        t.reduce.values as f64,
        t.bodies_stepped as f64,
        t.bodies_sent as f64,
        super::cluster::peak_rss_mib(),
        t.shell_bodies as f64,
        t.limited_shells as f64,
        t.bodies_held as f64,
        t.bodies_held_max as f64,
        t.restart_contacts as f64,
        t.loaded_bodies as f64,
        t.family_bodies_stepped as f64,
        t.family_bodies as f64,
        t.family_bodies_built as f64,
        t.family_contacts as f64,
        t.family_detected as f64,
        t.family_bodies_near as f64,
        t.peers.len() as f64,
    ];
    mine.extend(t.peers.iter().map(|&x| x as f64));
    mine.resize(H + p, -1.0);
    let counts = vec![H + p; p];
    let mut all = Vec::new();
    st.cluster.all_gather(&mine, &counts, &mut all);
    let ranks: Vec<serde_json::Value> = all
        .chunks_exact(H + p)
        .enumerate()
        .map(|(r, x)| {
            let peers: Vec<u32> = x[H..H + x[H - 1] as usize].iter().map(|&v| v as u32).collect();
            let subs: Vec<usize> = (0..st.rank_of.len()).filter(|&s| st.rank_of[s] == r as u32).collect();
            serde_json::json!({
                "rank": r,
                "cpu_seconds": x[0],
                "wait_cpu_seconds": x[1],
                "wait_seconds": x[2],
                "compute_cpu_seconds": x[3],
                "steps": x[4] as u64,
                "messages": x[5] as u64,
                "values": x[6] as u64,
                "rounds": x[7] as u64,
                "exchange_seconds": x[8],
                "reduce_seconds": x[9],
                "solve_seconds": x[10],
                "reduce_messages": x[11] as u64,
                "reduce_values": x[12] as u64,
                "bodies_stepped": x[13] as u64,
                "bodies_sent": x[14] as u64,
                "peak_rss_mib": x[15],
                "shell_bodies": x[16] as u64,
                "limited_shell_steps": x[17] as u64,
                "bodies_held": x[18] as u64,
                "bodies_held_max": x[19] as u64,
                "restart_contacts": x[20] as u64,
                "loaded_bodies": x[21] as u64,
                "family_bodies_stepped": x[22] as u64,
                "family_bodies": x[23] as u64,
                "family_bodies_built": x[24] as u64,
                "family_contacts": x[25] as u64,
                "family_detected": x[26] as u64,
                "family_bodies_near": x[27] as u64,
                "peers": peers,
                "last_subdomains": subs,
            })
        })
        .collect();
    let mut s = serde_json::to_string_pretty(&serde_json::json!({ "ranks": p, "per_rank": ranks })).expect("plain data");
    s.push('\n');
    s
}
