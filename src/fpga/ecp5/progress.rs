//! What each running nextpnr is doing, read from its log and shown on a spinner per seed
//! while `place_and_route_seeds` waits. The whole core takes one to three hours a seed on a
//! 2-core machine (docs/TIMING.md): placing, refining the placement, then routing, whose
//! arcs left say more than a clock running on.

use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How much of a log's end is read for its phase: the last lines only.
const TAIL_BYTES: u64 = 8192;

/// The phase a nextpnr-ecp5 log's end shows, from its last line that tells one (`None`
/// before any): packing, placing (HeAP's or the static placer's iterations), refining
/// (simulated annealing's), routing (router1's arcs left, router2's overused wires), finished.
pub fn phase(log_tail: &str) -> Option<String> {
    log_tail.lines().rev().find_map(phase_of_line)
}

fn phase_of_line(line: &str) -> Option<String> {
    let text = line.strip_prefix("Info:")?.trim();
    let number_after = |key: &str| -> Option<u64> {
        let rest = &text[text.find(key)? + key.len()..];
        rest.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok()
    };
    if text.starts_with("Program finished normally") {
        return Some("finished".into());
    }
    if text.starts_with("at iteration #") {
        let i = number_after("#")?;
        // HeAP's lines name the solve ("type ALL"), simulated annealing's the temperature.
        return Some(if text.contains("type ") {
            format!("placing, HeAP iteration {i}")
        } else {
            format!("refining the placement, iteration {i}")
        });
    }
    if text.starts_with("iter=") && text.contains("steplen=") {
        return Some(format!("placing (static), iteration {}", number_after("iter=")?));
    }
    if text.starts_with("iter=") {
        let overused = number_after("overused=")?;
        return Some(format!(
            "routing (router2), iteration {}, {} wires overused",
            number_after("iter=")?,
            thousands(overused)
        ));
    }
    // router1's table: "IterCnt | w/ripup wo/ripup | w/r wo/r | remaining arcs | batch total".
    let cols: Vec<&str> = text.split('|').map(str::trim).collect();
    if cols.len() >= 5 && cols[0].parse::<u64>().is_ok() {
        let left: u64 = cols[3].parse().ok()?;
        return Some(format!("routing, {} arcs left", thousands(left)));
    }
    if let Some(arcs) = text.strip_prefix("Routing ").and_then(|r| r.strip_suffix(" arcs.")) {
        return Some(format!("routing {} arcs", thousands(arcs.parse().ok()?)));
    }
    if text.starts_with("Routing globals") || text.starts_with("Running router2") {
        return Some("routing".into());
    }
    if text.starts_with("Running simulated annealing") {
        return Some("refining the placement".into());
    }
    if ["Packing", "Running HeAP", "Running Static", "Creating initial"].iter().any(|s| text.starts_with(s)) {
        return Some("packing and placing".into());
    }
    None
}

/// 366459 → "366,459" (indicatif's grouping).
fn thousands(n: u64) -> String {
    indicatif::HumanCount(n).to_string()
}

/// The last `TAIL_BYTES` of `path`, or `None` while it does not exist.
fn tail(path: &Path) -> Option<String> {
    let mut f = std::fs::File::open(path).ok()?;
    let len = f.metadata().ok()?.len();
    f.seek(SeekFrom::Start(len.saturating_sub(TAIL_BYTES))).ok()?;
    let mut bytes = Vec::new();
    f.read_to_end(&mut bytes).ok()?;
    Some(String::from_utf8_lossy(&bytes).into_owned())
}

/// Runs `work` while a spinner per seed shows the phase of `dir/nextpnr.log` (`logs`: seed
/// and its folder), refreshed each second; a seed whose log is not there yet is waiting.
/// Earlier runs' logs are removed first, so a queued seed never shows a finished run's phase.
/// The spinners draw only on a terminal (indicatif hides them otherwise); `work` is given a
/// `say` that prints a line above them (or plainly, when they are hidden).
pub fn watching<R>(logs: &[(u64, PathBuf)], work: impl FnOnce(&(dyn Fn(&str) + Sync)) -> R) -> R {
    for (_, dir) in logs {
        let _ = std::fs::remove_file(dir.join("nextpnr.log"));
    }
    let all = indicatif::MultiProgress::new();
    let style = indicatif::ProgressStyle::with_template("{spinner} nextpnr seed {prefix}: {elapsed} {msg}")
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner());
    let bars: Vec<_> = logs
        .iter()
        .map(|(seed, _)| {
            let bar = all.add(indicatif::ProgressBar::new_spinner().with_style(style.clone()));
            bar.set_prefix(seed.to_string());
            bar.set_message("waiting");
            bar
        })
        .collect();
    let stop = AtomicBool::new(false);
    std::thread::scope(|scope| {
        scope.spawn(|| {
            while !stop.load(Ordering::Relaxed) {
                for ((_, dir), bar) in logs.iter().zip(&bars) {
                    if let Some(p) = tail(&dir.join("nextpnr.log")).as_deref().and_then(phase) {
                        bar.set_message(p);
                    }
                    bar.tick();
                }
                std::thread::sleep(Duration::from_millis(250));
            }
        });
        let say = |line: &str| {
            if all.is_hidden() || all.println(line).is_err() {
                eprintln!("{line}");
            }
        };
        let out = work(&say);
        stop.store(true, Ordering::Relaxed);
        for bar in &bars {
            bar.finish_and_clear();
        }
        out
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    // Lines as nextpnr-ecp5 0.11 writes them (from the fitted core's logs, session 27).
    const HEAP: &str = "Info: Running HeAP analytic placer.\n\
        Info:     at iteration #16, type ALL: wirelen solved = 327028, spread = 675143, legal = 824544; time = 17.49s\n";
    const STATIC: &str = "Info: Running Static placer...\n\
        Info: iter=692 steplen=2.198215 a=348.459717 penalty=[137.52, 137.52, 137.52, 137.52]\n\
        Info:    update_chains distance 2402.53\n\
        Info: overlap: COMB=10.3%, FF=1.8%, RAM=0.0%, MUL=0.0%\n";
    const SA: &str = "Info: Running simulated annealing placer for refinement.\n\
        Info:   at iteration #20: temp = 0.000000, timing cost = 4765, wirelen = 658952\n";
    const ROUTER1: &str = "Info: Routing 366459 arcs.\n\
        Info:            |   (re-)routed arcs  |   delta    | remaining|       time spent     |\n\
        Info:    IterCnt |  w/ripup   wo/ripup |  w/r  wo/r |      arcs| batch(sec) total(sec)|\n\
        Info:     479000 |   105260     369694 |  287   713 |    139321|       8.70    1886.56|\n";
    const ROUTER2: &str = "Info: Running main router loop...\n\
        Info:     iter=11 wires=1566611 overused=19635 overuse=19900 archfail=NA\n";

    #[test]
    fn a_logs_phase_is_its_last_line_that_tells_one() {
        assert_eq!(phase("").as_deref(), None);
        assert_eq!(phase("Info: Packing IOs..\n").as_deref(), Some("packing and placing"));
        assert_eq!(phase(HEAP).as_deref(), Some("placing, HeAP iteration 16"));
        assert_eq!(phase(&format!("{HEAP}{SA}")).as_deref(), Some("refining the placement, iteration 20"));
        assert_eq!(phase(&STATIC[..31]).as_deref(), Some("packing and placing"));
        assert_eq!(phase(STATIC).as_deref(), Some("placing (static), iteration 692"));
        assert_eq!(phase(&format!("{SA}Info: Routing globals...\n")).as_deref(), Some("routing"));
        assert_eq!(phase(&ROUTER1[..27]).as_deref(), Some("routing 366,459 arcs"));
        assert_eq!(phase(ROUTER1).as_deref(), Some("routing, 139,321 arcs left"));
        assert_eq!(phase(ROUTER2).as_deref(), Some("routing (router2), iteration 11, 19,635 wires overused"));
        // A line cut by the tail's start, or one that tells nothing, leaves the earlier phase.
        let cut = format!("{ROUTER1}Info: Max frequency for clock 'clk': 95.05 MHz (FAIL at 150.00 MHz)\n");
        assert_eq!(phase(&cut).as_deref(), Some("routing, 139,321 arcs left"));
        assert_eq!(phase(&format!("{ROUTER1}Info: Program finished normally.\n")).as_deref(), Some("finished"));
    }

    #[test]
    fn large_counts_are_grouped_by_thousands() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(366459), "366,459");
        assert_eq!(thousands(1566611), "1,566,611");
    }

    #[test]
    fn the_tail_is_the_logs_end_and_a_missing_log_has_none() {
        let dir = std::env::temp_dir().join(format!("fxrt-progress-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let log = dir.join("nextpnr.log");
        assert_eq!(tail(&log), None);
        let filler = "Info: something else\n".repeat(1000);
        std::fs::write(&log, format!("{HEAP}{filler}{SA}")).unwrap();
        let t = tail(&log).unwrap();
        assert_eq!(t.len() as u64, TAIL_BYTES);
        assert!(!t.contains("HeAP"), "only the end is read");
        assert_eq!(phase(&t).as_deref(), Some("refining the placement, iteration 20"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
