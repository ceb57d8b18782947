//! `fxrt synth`: Xilinx area estimates from yosys `synth_xilinx` — Virtex-5 (`xc5v`, the
//! thesis's device) and 7-series (`xc7`, e.g. an Artix-7 100T) as a second reference.

use crate::error::{Error, Result};
use crate::rtl::emit;
use crate::rtl::netlist::Module;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Area {
    pub module: String,
    /// LUT1–LUT6 used as logic.
    pub luts: u64,
    /// LUTs used as shift registers (SRL16E, SRLC32E).
    pub srl_luts: u64,
    /// Flip-flops (FD*).
    pub ffs: u64,
    pub dsp48e: u64,
    /// Block RAMs (RAMB18 count; a RAMB36 counts as 2).
    pub bram18: u64,
    /// Distributed-RAM cells (RAM32M and the like: LUTs used as small RAMs).
    pub lutram_cells: u64,
    pub carry4: u64,
    /// Every cell type yosys reported.
    pub cells: BTreeMap<String, u64>,
}

/// Counts the mapped cells of yosys's `stat -json` output.
pub fn area_from_stat(module: &str, stat: &serde_json::Value) -> Area {
    let mut a = Area { module: module.to_string(), ..Default::default() };
    if let Some(cells) = stat["design"]["num_cells_by_type"].as_object() {
        for (k, v) in cells {
            let n = v.as_u64().unwrap_or(0);
            a.cells.insert(k.clone(), n);
            match k.as_str() {
                k if k.starts_with("LUT") => a.luts += n,
                "SRL16E" | "SRLC32E" => a.srl_luts += n,
                k if k.starts_with("FD") => a.ffs += n,
                k if k.starts_with("DSP48") => a.dsp48e += n,
                k if k.starts_with("RAMB36") => a.bram18 += 2 * n,
                k if k.starts_with("RAMB18") => a.bram18 += n,
                k if k.starts_with("RAM32") || k.starts_with("RAM64") || k.starts_with("RAM128") => a.lutram_cells += n,
                "CARRY4" => a.carry4 += n,
                _ => {}
            }
        }
    }
    a
}

/// Synthesises `m` for Virtex-5 in `dir` (kept for inspection) and returns its area.
pub fn synth_xc5v(m: &Module, dir: &Path) -> Result<Area> {
    synth_xilinx(m, "xc5v", dir)
}

/// Synthesises `m` with `synth_xilinx -family FAMILY` (xc5v or xc7) in `dir`.
pub fn synth_xilinx(m: &Module, family: &str, dir: &Path) -> Result<Area> {
    let io = |e: std::io::Error| Error::file(dir, e.to_string());
    let files = emit::design_files(m, "v");
    let mut set = crate::io::OutputSet::new();
    set.extend(files.iter().map(|(file, text)| (dir.join(file), text)))?;
    set.commit()?;
    let names: Vec<&str> = files.iter().map(|f| f.0.as_str()).filter(|f| emit::is_source(f)).collect();
    // -flatten: one area figure for the whole hierarchy.
    let script = format!(
        "read_verilog {}; synth_xilinx -family {family} -flatten -top {}; tee -q -o stat.json stat -json",
        names.join(" "),
        m.name
    );
    let out = Command::new("yosys")
        .args(["-q", "-l", "yosys.log", "-p", &script])
        .current_dir(dir)
        .output()
        .map_err(|e| Error::new("yosys", format!("cannot run (scripts/install-deps.sh installs it): {e}")))?;
    if !out.status.success() {
        return Err(Error::new("yosys", format!("synthesis failed, see {}", dir.join("yosys.log").display())));
    }
    let text = std::fs::read_to_string(dir.join("stat.json")).map_err(io)?;
    let stat: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| Error::file(&dir.join("stat.json"), e.to_string()))?;
    Ok(area_from_stat(&m.name, &stat))
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_cells_by_kind() {
        let stat = serde_json::json!({ "design": { "num_cells_by_type": { "LUT2": 3, "LUT6": 4, "FDRE": 5, "FDSE": 1, "DSP48E": 2, "RAMB36E1": 1, "SRLC32E": 7, "CARRY4": 9, "IBUF": 3, "RAM32M": 2 } } });
        let a = super::area_from_stat("x", &stat);
        assert_eq!((a.luts, a.ffs, a.dsp48e, a.bram18, a.srl_luts, a.carry4, a.lutram_cells), (7, 6, 2, 2, 7, 9, 2));
    }
}
