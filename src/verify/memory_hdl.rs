//! The memory model in VHDL and Verilog, for the testbenches (`testbenches/axi_mem_model.*`):
//! `verify::memory::MemoryModel`'s definition written out for GHDL, Icarus and Verilator, so a
//! core with its scene in external memory sees the same beats on the same clocks in every
//! simulator. Rendered by askama (testbench boilerplate, never a datapath).

use super::memory::MemoryTiming;
use askama::Template;

/// The model's module name.
pub const MODEL: &str = "fxrt_axi_mem_model";

#[derive(Template)]
#[template(path = "axi_mem_model.tpl", escape = "none")]
struct MemModel<'a> {
    vhdl: bool,
    name: &'a str,
    latency: u32,
    outstanding: u32,
    jitter: u32,
    pauses: u32,
    seed: u32,
    data_bits: u32,
    addr_bits: u32,
    base: u64,
    depth: usize,
    image: &'a str,
    image_bits: &'a str,
}

/// The model's file and its image file (hex for Verilog, bit strings for VHDL), as (file name,
/// contents): the image at byte address `base`, read in beats of `data_bits`.
pub fn model_files(
    timing: &MemoryTiming,
    data_bits: u32,
    addr_bits: u32,
    base: u64,
    image: &[u8],
    vhdl: bool,
) -> Vec<(String, String)> {
    let beat = (data_bits / 8) as usize;
    let beats: Vec<&[u8]> = image.chunks(beat).collect();
    let (hex_name, bits_name) = ("mem_image.hex", "mem_image.txt");
    let t = MemModel {
        vhdl,
        name: MODEL,
        latency: timing.latency,
        outstanding: timing.outstanding,
        jitter: timing.extra_delay,
        pauses: timing.pause_in_256,
        seed: if timing.seed == 0 { 1 } else { timing.seed },
        data_bits,
        addr_bits,
        base,
        depth: beats.len().max(1),
        image: hex_name,
        image_bits: bits_name,
    };
    let text = t.render().expect("memory model template renders") + "\n";
    // A beat, most significant byte first (the last chunk padded with zero bytes).
    let word = |c: &[u8]| -> Vec<u8> { (0..beat).rev().map(|k| c.get(k).copied().unwrap_or(0)).collect() };
    let data = if vhdl {
        beats.iter().map(|c| word(c).iter().map(|b| format!("{b:08b}")).collect::<String>() + "\n").collect()
    } else {
        beats.iter().map(|c| word(c).iter().map(|b| format!("{b:02x}")).collect::<String>() + "\n").collect()
    };
    let ext = if vhdl { "vhd" } else { "v" };
    vec![(format!("{MODEL}.{ext}"), text), ((if vhdl { bits_name } else { hex_name }).to_string(), data)]
}
