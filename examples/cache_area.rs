//! Place and route of the memory side at the sizes docs/MEMORY.md plans for the default core
//! with its scene in external memory: the AXI read master, one node cache per traversal unit
//! (two of 32 KB) and a triangle cache of 64 KB, 128-byte lines, two ways, 64-bit port, line
//! numbers for teapot-fine — on the LFE5U-85F (yosys + nextpnr-ecp5), behind the usual
//! pin wrapper. Prints the resources and the clock; the caches' lookups and answers are ports.
//!
//! cargo run --release --example cache_area -- [--seed 1] [--mhz 150] [--dir target/cache_area]

use fxrt::cores::axi_read::AxiReadParams;
use fxrt::cores::cache::CacheParams;
use fxrt::fpga::ecp5::{Tools, place_and_route};
use fxrt::verify::memory_tests::mem_side;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let opt =
        |name: &str, d: &str| args.iter().position(|a| a == name).map(|i| args[i + 1].clone()).unwrap_or(d.into());
    let seed: u64 = opt("--seed", "1").parse().unwrap();
    let mhz: f64 = opt("--mhz", "150").parse().unwrap();
    let dir = std::path::PathBuf::from(opt("--dir", "target/cache_area"));
    std::fs::create_dir_all(&dir).unwrap();
    let node = CacheParams {
        record_bits: 76,
        record_beats: 2,
        records_per_line: 8,
        line_beats: 16,
        data_bits: 64,
        sets: 128,
        ways: 2,
        line_bits: 13,
        inflight: 8,
    };
    let tri = CacheParams { record_bits: 297, record_beats: 5, records_per_line: 3, sets: 256, line_bits: 15, ..node };
    let shapes = [node, node, tri];
    let ap = AxiReadParams { addr_bits: 32, data_bits: 64, line_beats: 16, outstanding: 16, queue: 8 };
    let caches: Vec<(CacheParams, u64)> = shapes.iter().map(|&p| (p, 0)).collect();
    let m = mem_side("fxrt_mem_side", &ap, &caches);
    let bits: u64 = shapes.iter().map(|p| p.bits()).sum();
    eprintln!("cache bits (records + tags): {bits} ({} KB)", bits / 8 / 1024);
    let tools = Tools::require().unwrap_or_else(|e| panic!("{e}"));
    let t = place_and_route(&tools, &m, None, mhz, seed, &dir).unwrap_or_else(|e| panic!("{e}"));
    println!("{}", serde_json::to_string_pretty(&t).unwrap());
}
