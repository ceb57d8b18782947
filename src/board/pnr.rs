//! The ULX3S bitstream: yosys `synth_ecp5` of the board top and its logic (the ECP5 sources of
//! `fpga::ecp5`), nextpnr-ecp5 with the board's LPF — its 25 MHz `FREQUENCY` constraint,
//! carried through the PLL to the board clock — and ecppack.

use super::{Board, BoardDesign};
use crate::error::{Error, Result};
use crate::fpga::ecp5::{Tools, nextpnr, read_report, run, synthesize, write_sources};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What nextpnr measured of a board design, and where the bitstream is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BoardTiming {
    pub top: String,
    pub board: String,
    pub part: String,
    /// The board clock (the PLL's output) and the clock nextpnr reached on it.
    pub clock_mhz: f64,
    pub fmax_mhz: f64,
    /// Every clock domain nextpnr timed reached its constraint.
    pub met: bool,
    /// Each clock net: (name, achieved MHz, constraint MHz).
    pub domains: Vec<(String, f64, f64)>,
    pub lut4: u64,
    pub ff: u64,
    pub mult18: u64,
    pub dp16kd: u64,
    pub seed: u64,
    pub yosys: String,
    pub nextpnr: String,
    /// The bitstream's file name (in the build folder and copied beside the HDL).
    pub bitstream: String,
}

/// `ecppack` beside nextpnr (the YoWASP package brings both).
fn ecppack(tools: &Tools) -> PathBuf {
    match tools.nextpnr.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => dir.join("yowasp-ecppack"),
        None => PathBuf::from("yowasp-ecppack"),
    }
}

/// Places and routes `d` (a ULX3S design) in `dir` with placement seed `seed` and packs the
/// bitstream `<top>.bit` there.
pub fn bitstream(tools: &Tools, d: &BoardDesign, seed: u64, dir: &Path) -> Result<BoardTiming> {
    if d.board != Board::Ulx3s {
        return Err(Error::param(
            "board",
            format!("{}: the bitstream comes from ISE (the .tcl project)", d.board.name()),
        ));
    }
    let mut sources = write_sources(&d.logic, dir)?;
    let top_file = format!("{}.v", d.top);
    let (lpf, lpf_text) = d.constraints();
    let mut files = crate::io::OutputSet::new();
    files.add(&dir.join(&top_file), d.top_hdl("v").as_bytes())?;
    files.add(&dir.join(&lpf), lpf_text.as_bytes())?;
    files.commit()?;
    sources.push(top_file);
    synthesize(tools, dir, &sources, &d.top)?;
    nextpnr(tools, dir, &["--lpf", &lpf, "--textcfg", "design.config"], seed)?;
    let bit = format!("{}.bit", d.top);
    run(&ecppack(tools), &["--compress", "design.config", &bit], dir, "nextpnr.log")?;
    let report = read_report(dir)?;
    let (yosys, nextpnr) = tools.versions();
    Ok(timing_of(&report, d, seed, yosys, nextpnr, bit))
}

/// The figures of nextpnr's `--report` for `d`.
pub fn timing_of(
    r: &serde_json::Value,
    d: &BoardDesign,
    seed: u64,
    yosys: String,
    nextpnr: String,
    bitstream: String,
) -> BoardTiming {
    let used = |cell: &str| r["utilization"][cell]["used"].as_u64().unwrap_or(0);
    let domains: Vec<(String, f64, f64)> = r["fmax"]
        .as_object()
        .map(|o| {
            o.iter()
                .map(|(net, v)| {
                    (net.clone(), v["achieved"].as_f64().unwrap_or(0.0), v["constraint"].as_f64().unwrap_or(0.0))
                })
                .collect()
        })
        .unwrap_or_default();
    let fmax = domains.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
    BoardTiming {
        top: d.top.clone(),
        board: d.board.name().into(),
        part: "LFE5U-85F-6BG381C".into(),
        clock_mhz: d.clock.mhz,
        fmax_mhz: if fmax.is_finite() { (fmax * 100.0).round() / 100.0 } else { 0.0 },
        // A design with no timed clock has not been checked.
        met: !domains.is_empty() && domains.iter().all(|x| x.1 >= x.2),
        domains,
        lut4: used("TRELLIS_COMB"),
        ff: used("TRELLIS_FF"),
        mult18: used("MULT18X18D"),
        dp16kd: used("DP16KD"),
        seed,
        yosys,
        nextpnr,
        bitstream,
    }
}
