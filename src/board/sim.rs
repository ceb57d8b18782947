//! The board top in a simulator: `testbenches/board_tb.v` around the top and its logic, the
//! vendor primitives from `testbenches/primitives` (stand-ins: the PLL passes its clock on).
//! The testbench reads only the pins: the LEDs say whether each frame's checksum was the
//! golden model's.

use super::{Board, BoardDesign};
use askama::Template;
use std::path::Path;
use std::process::Command;

/// The stand-ins of the vendor primitives a board's top instantiates, in `ext` ("v" or
/// "vhd"): (file name, text).
pub fn primitives(board: Board, ext: &str) -> (&'static str, &'static str) {
    match (board, ext) {
        (Board::Ulx3s, "v") => ("ecp5_primitives.v", include_str!("../../testbenches/primitives/ecp5.v")),
        (Board::Ulx3s, _) => ("ecp5_primitives.vhd", include_str!("../../testbenches/primitives/ecp5.vhd")),
        (Board::Ml509, "v") => ("virtex5_primitives.v", include_str!("../../testbenches/primitives/virtex5.v")),
        (Board::Ml509, _) => ("virtex5_primitives.vhd", include_str!("../../testbenches/primitives/virtex5.vhd")),
    }
}

struct TbFields<'a> {
    top: &'a str,
    board: &'a str,
    pressed: &'a str,
    released: &'a str,
    pressed_vhdl: &'a str,
    released_vhdl: &'a str,
    press_at: u64,
    max_cycles: u64,
}

super::board_template!(TbVerilog, TbFields, "board_tb.v");
super::board_template!(TbVhdl, TbFields, "board_tb.vhd");

/// The testbench for `d` (built with LED shift 0) in `ext` ("v" or "vhd"): the button
/// pressed `press_at` clocks into the second frame, at most `max_cycles` clocks.
pub fn testbench(d: &BoardDesign, ext: &str, press_at: u64, max_cycles: u64) -> String {
    let high = d.board == Board::Ulx3s;
    let bit = |v: bool, vhdl: bool| match (v, vhdl) {
        (true, false) => "1'b1",
        (false, false) => "1'b0",
        (true, true) => "'1'",
        (false, true) => "'0'",
    };
    let f = TbFields {
        top: &d.top,
        board: d.board.name(),
        pressed: bit(high, false),
        released: bit(!high, false),
        pressed_vhdl: bit(high, true),
        released_vhdl: bit(!high, true),
        press_at,
        max_cycles,
    };
    let text = if ext == "v" { TbVerilog(&f).render() } else { TbVhdl(&f).render() };
    text.expect("board testbench renders") + "\n"
}

/// Writes the design in `ext` ("v" or "vhd"), the primitives' stand-ins and the testbench
/// into `dir`; returns the source files in compile order (testbench last).
pub fn write(
    dir: &Path,
    d: &BoardDesign,
    ext: &str,
    press_at: u64,
    max_cycles: u64,
) -> crate::error::Result<Vec<String>> {
    let mut files = crate::io::OutputSet::new();
    let mut sources = Vec::new();
    let (prim, text) = primitives(d.board, ext);
    files.add(&dir.join(prim), text.as_bytes())?;
    sources.push(prim.to_string());
    for (name, text) in d.files(ext == "vhd", ext == "v") {
        files.add(&dir.join(&name), text.as_bytes())?;
        if name.ends_with(&format!(".{ext}")) {
            sources.push(name);
        }
    }
    let tb = format!("board_tb.{ext}");
    files.add(&dir.join(&tb), testbench(d, ext, press_at, max_cycles).as_bytes())?;
    files.commit()?;
    sources.push(tb);
    Ok(sources)
}

/// GHDL on the VHDL files `write` wrote: (PASS reported, the whole output).
pub fn ghdl(dir: &Path, sources: &[String]) -> Result<(bool, String), String> {
    let step = |args: &[&str], extra: &[String]| -> Result<String, String> {
        let o =
            Command::new("ghdl").args(args).args(extra).current_dir(dir).output().map_err(|e| format!("ghdl: {e}"))?;
        let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
        if o.status.success() { Ok(text) } else { Err(format!("ghdl {}: {text}", args[0])) }
    };
    step(&["-a", "--std=93c", "--workdir=."], sources)?;
    step(&["-e", "--std=93c", "--workdir=.", "board_tb"], &[])?;
    let text = step(&["-r", "--std=93c", "--workdir=.", "board_tb"], &[])?;
    Ok((text.lines().any(|l| l.trim_end().ends_with("(report note): PASS")), text))
}

/// Icarus Verilog on the files `write_verilog` wrote: (PASS printed, the whole output).
pub fn icarus(dir: &Path, sources: &[String]) -> Result<(bool, String), String> {
    let compile = Command::new("iverilog")
        .args(["-g2005", "-o", "board_tb.vvp", "-s", "board_tb"])
        .args(sources)
        .current_dir(dir)
        .output()
        .map_err(|e| format!("iverilog: {e}"))?;
    if !compile.status.success() {
        return Err(format!("iverilog: {}", String::from_utf8_lossy(&compile.stderr)));
    }
    let run =
        Command::new("vvp").args(["-n", "board_tb.vvp"]).current_dir(dir).output().map_err(|e| format!("vvp: {e}"))?;
    let text = String::from_utf8_lossy(&run.stdout).to_string();
    Ok((text.lines().any(|l| l.trim() == "PASS"), text))
}
