//! Several placement seeds of one netlist: synthesised once, placed and routed per seed (in
//! parallel, one nextpnr a core), reported as the median seed with the spread. A clock figure
//! is the median of several seeds, never the best (nextpnr's placement spreads one netlist
//! over tens of MHz: docs/TIMING.md).

use super::{
    PIN_REGS, Timing, Tools, nextpnr, read_report, slow_paths_of, synthesize, timing_from_report, wrapper,
    write_sources,
};
use crate::error::{Error, Result};
use crate::rtl::Module;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// The most seeds one run takes (each is minutes to an hour of place and route).
pub const MAX_SEEDS: usize = 16;

/// Parses `--seeds`: one seed, a range `A..B` (both included) or a list `A,B,C`; distinct,
/// at most `MAX_SEEDS`.
pub fn parse_seeds(text: &str) -> Result<Vec<u64>> {
    let bad = |why: String| Error::param("seeds", format!("'{text}': {why}"));
    let number =
        |s: &str| s.trim().parse::<u64>().map_err(|_| bad(format!("'{}' is not a seed (0, 1, 2, …)", s.trim())));
    let seeds = match text.split_once("..") {
        Some((a, b)) => {
            let (a, b) = (number(a)?, number(b)?);
            if b < a {
                return Err(bad("the range is empty".into()));
            }
            if b - a >= MAX_SEEDS as u64 {
                return Err(bad(format!("more than {MAX_SEEDS} seeds")));
            }
            (a..=b).collect()
        }
        None => text.split(',').map(number).collect::<Result<Vec<_>>>()?,
    };
    if seeds.len() > MAX_SEEDS {
        return Err(bad(format!("more than {MAX_SEEDS} seeds")));
    }
    let mut sorted = seeds.clone();
    sorted.sort_unstable();
    sorted.dedup();
    if sorted.len() != seeds.len() {
        return Err(bad("a seed is repeated".into()));
    }
    Ok(seeds)
}

/// One seed's outcome, as the summary lists it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SeedFmax {
    pub seed: u64,
    pub fmax_mhz: f64,
    /// The slowest path's delay, ns, and where it starts and ends.
    pub delay_ns: f64,
    pub start: String,
    pub end: String,
}

/// A module placed at several seeds: the median seed's whole figures (flattened, so readers of
/// a one-seed report read it alike), every seed's Fmax, and the spread.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Placed {
    #[serde(flatten)]
    pub median: Timing,
    /// Every seed, in the order asked.
    pub seeds: Vec<SeedFmax>,
    pub fmax_min_mhz: f64,
    pub fmax_max_mhz: f64,
}

impl Placed {
    /// The median of `timings` (the lower middle one for an even count: a seed's own figures,
    /// and the cautious one) with the spread.
    pub fn of(timings: Vec<Timing>) -> Placed {
        assert!(!timings.is_empty(), "at least one seed");
        let seeds: Vec<SeedFmax> = timings
            .iter()
            .map(|t| SeedFmax {
                seed: t.seed,
                fmax_mhz: t.fmax_mhz,
                delay_ns: t.critical_path.delay_ns,
                start: t.critical_path.start.clone(),
                end: t.critical_path.end.clone(),
            })
            .collect();
        let mut order: Vec<&Timing> = timings.iter().collect();
        order.sort_by(|a, b| a.fmax_mhz.total_cmp(&b.fmax_mhz).then(a.seed.cmp(&b.seed)));
        let median = order[(order.len() - 1) / 2].clone();
        let fmax_min_mhz = order[0].fmax_mhz;
        let fmax_max_mhz = order[order.len() - 1].fmax_mhz;
        Placed { median, seeds, fmax_min_mhz, fmax_max_mhz }
    }
}

/// Where seed `seed` of `seeds` is placed: `dir` itself for a single seed, else `dir/seed-N`.
pub fn seed_dir(dir: &Path, seeds: &[u64], seed: u64) -> PathBuf {
    if seeds.len() == 1 { dir.to_path_buf() } else { dir.join(format!("seed-{seed}")) }
}

/// Synthesises `m` (in its pin wrapper) once in `dir`, then places and routes it at each of
/// `seeds` in `dir/seed-N` (the netlist copied there), `jobs` nextpnr runs at a time, and
/// reports each seed as it ends through `done`.
pub fn place_and_route_seeds(
    tools: &Tools,
    m: &Module,
    latency: Option<u32>,
    target_mhz: f64,
    seeds: &[u64],
    jobs: usize,
    dir: &Path,
    done: &(dyn Fn(&Timing) + Sync),
) -> Result<Placed> {
    let top = wrapper(&Rc::new(m.clone()));
    let pins = (PIN_REGS.0 + PIN_REGS.1) as u64;
    let out_bits: u32 = m.outputs.iter().map(|o| m.sig(o.1).ty.width).sum();
    let wrapper_ff: u64 =
        m.inputs.iter().map(|&i| m.sig(i).ty.width as u64).sum::<u64>() + 1 + pins + super::xor_tree(out_bits).1 as u64;
    let sources = write_sources(&top, dir)?;
    synthesize(tools, dir, &sources, &top.name)?;
    let netlist_sha256 = super::netlist_hash(m);
    // The module itself (Rc inside) stays on this thread; the workers need only its name.
    let name = m.name.clone();
    let (yosys, nextpnr_version) = tools.versions();
    let place = |seed: u64| -> Result<Timing> {
        let seed_dir = seed_dir(dir, seeds, seed);
        if seeds.len() > 1 {
            std::fs::create_dir_all(&seed_dir).map_err(|e| Error::file(&seed_dir, e.to_string()))?;
            let json = dir.join("design.json");
            std::fs::copy(&json, seed_dir.join("design.json")).map_err(|e| Error::file(&json, e.to_string()))?;
        }
        nextpnr(tools, &seed_dir, &["--freq", &format!("{target_mhz}")], seed)?;
        let report = read_report(&seed_dir)?;
        let mut t = timing_from_report(
            &report,
            &name,
            target_mhz,
            latency,
            wrapper_ff,
            seed,
            yosys.clone(),
            nextpnr_version.clone(),
        );
        t.netlist_sha256 = netlist_sha256.clone();
        t.placer = tools.placer.name().to_string();
        let slowest = slow_paths_of(&seed_dir, target_mhz)?;
        (t.groups_over, t.endpoints_over) = (Some(slowest.groups_over), Some(slowest.endpoints_over));
        t.slow_paths = slowest.paths;
        done(&t);
        Ok(t)
    };
    // A shared queue of seeds, `jobs` workers: each nextpnr is single-threaded here.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<std::sync::Mutex<Option<Result<Timing>>>> = seeds.iter().map(|_| Default::default()).collect();
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, seeds.len()) {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some(&seed) = seeds.get(i) else { break };
                    *results[i].lock().unwrap() = Some(place(seed));
                }
            });
        }
    });
    let timings =
        results.into_iter().map(|r| r.into_inner().unwrap().expect("every seed ran")).collect::<Result<_>>()?;
    Ok(Placed::of(timings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_are_one_a_range_or_a_list() {
        assert_eq!(parse_seeds("4").unwrap(), vec![4]);
        assert_eq!(parse_seeds("1..5").unwrap(), vec![1, 2, 3, 4, 5]);
        assert_eq!(parse_seeds("3,1,7").unwrap(), vec![3, 1, 7]);
        for bad in ["", "a", "5..1", "1..40", "1,1", "1,-2", "1..", "2.5"] {
            let e = parse_seeds(bad).unwrap_err();
            assert_eq!(e.subject, "--seeds", "{bad}");
        }
    }

    fn timing(seed: u64, fmax_mhz: f64) -> Timing {
        Timing { seed, fmax_mhz, ..Timing::default() }
    }

    #[test]
    fn the_median_seed_is_reported_with_the_spread() {
        let p = Placed::of(vec![timing(1, 90.0), timing(2, 70.0), timing(3, 100.0)]);
        assert_eq!((p.median.seed, p.median.fmax_mhz, p.fmax_min_mhz, p.fmax_max_mhz), (1, 90.0, 70.0, 100.0));
        assert_eq!(p.seeds.iter().map(|s| s.seed).collect::<Vec<_>>(), vec![1, 2, 3]);
        // An even count: the lower middle seed, never the best.
        let p = Placed::of(vec![timing(1, 90.0), timing(2, 70.0), timing(3, 100.0), timing(4, 95.0)]);
        assert_eq!(p.median.seed, 1);
        let one = Placed::of(vec![timing(5, 80.0)]);
        assert_eq!((one.median.seed, one.fmax_min_mhz, one.fmax_max_mhz), (5, 80.0, 80.0));
        // Flattened: a one-seed reader finds the median's figures where it always did.
        let v = serde_json::to_value(&p).unwrap();
        assert_eq!((v["fmax_mhz"].as_f64(), v["seed"].as_u64()), (Some(90.0), Some(1)));
    }
}
