//! One netlist, four simulators: a module using every operator, a pipeline-stage block, a
//! state-machine block and delay lines is simulated in Rust, and its VHDL and Verilog run under
//! GHDL, Icarus and Verilator against the Rust transcript; both languages also pass Verilator's
//! lint, `ghdl --synth` and yosys. Each tool that is not installed is reported as skipped.

use fxrt::rtl::emit::{design_files, verilog, vhdl};
use fxrt::rtl::netlist::BlockKind;
use fxrt::rtl::{BinOp, Module, Ty, UnOp};
use fxrt::verify::simulators::Simulator;
use fxrt::verify::testbench::{Stimulus, record, replay};
use std::io::Write;

fn all_ops() -> Module {
    let mut m = Module::new("ops_check");
    let a = m.input("a", Ty::s(13));
    let b = m.input("b", Ty::s(13));
    let c = m.input("c", Ty::u(7));
    let d = m.input("d", Ty::u(7));
    let sel = m.input("sel", Ty::BIT);
    let wide = m.input("wide", Ty::s(70));
    let out = |m: &mut Module, name: &str, s| m.output(name, s);
    for (name, op) in [
        ("add", BinOp::Add),
        ("sub", BinOp::Sub),
        ("and", BinOp::And),
        ("or", BinOp::Or),
        ("xor", BinOp::Xor),
        ("mul", BinOp::Mul),
        ("eq", BinOp::Eq),
        ("lt", BinOp::Lt),
        ("le", BinOp::Le),
        ("ne", BinOp::Ne),
    ] {
        let s = m.bin(&format!("{name}_s"), op, a, b);
        out(&mut m, &format!("o_{name}_s"), s);
        let u = m.bin(&format!("{name}_u"), op, c, d);
        out(&mut m, &format!("o_{name}_u"), u);
    }
    for (name, op) in [
        ("not", UnOp::Not),
        ("neg", UnOp::Neg),
        ("shl", UnOp::Shl(3)),
        ("shr", UnOp::Shr(5)),
        ("slice", UnOp::Slice { lsb: 2, width: 6 }),
        ("grow", UnOp::Resize(20)),
        ("shrink", UnOp::Resize(9)),
        ("cast", UnOp::AsUnsigned),
    ] {
        let s = m.un(&format!("{name}_s"), op, a);
        out(&mut m, &format!("o_{name}_s"), s);
    }
    for (name, op) in [("neg", UnOp::Neg), ("shr", UnOp::Shr(2)), ("grow", UnOp::Resize(11)), ("cast", UnOp::AsSigned)]
    {
        let u = m.un(&format!("{name}_u"), op, c);
        out(&mut m, &format!("o_{name}_u"), u);
    }
    let wm = m.mul("wide_mul", wide, a);
    out(&mut m, "o_wide_mul", wm);
    let ws = m.shr("wide_shr", wide, 40);
    let wt = m.resize("wide_low", ws, 17);
    out(&mut m, "o_wide", wt);
    let mx = m.mux("mux", sel, c, d);
    out(&mut m, "o_mux", mx);
    let cat = m.concat("cat", &[c, sel, a]);
    out(&mut m, "o_cat", cat);
    let k = m.konst("k", Ty::s(13), -1234);
    let ak = m.add("a_plus_k", a, k);
    // Registers: a pipeline stage (a block: its own process), one with enable and reset, and a
    // ROM read.
    m.begin_block("s1", "the sum and its tag, registered", BlockKind::Stage);
    let r1 = m.delay("r1", ak);
    // A delay line in the stage: a shift register of five words.
    let dl = m.delay_line("tag_late", wide, 5);
    let r1_low = m.slice("r1_low", r1, 0, 4);
    m.end_block();
    out(&mut m, "o_r1", r1);
    out(&mut m, "o_r1_low", r1_low);
    out(&mut m, "o_tag_late", dl);
    // A delay line in no block, of a one-bit signal.
    let sel_late = m.delay_line("sel_late", sel, 3);
    out(&mut m, "o_sel_late", sel_late);
    state_machine(&mut m, sel, c, d);
    let acc = m.reg("acc", Ty::u(7), Some(5));
    let accn = m.add("acc_next", acc, c);
    m.connect(acc, accn, Some(sel));
    out(&mut m, "o_acc", acc);
    let rom = m.rom("table", 9, (0..37u128).map(|i| (i * 97 + 3) % 512).collect());
    let addr = m.slice("addr", d, 0, 6);
    let q = m.rom_read("rom_q", rom, addr);
    out(&mut m, "o_rom", q);
    // A RAM written from the inputs and read back (read-first on the same address).
    let ram = m.ram("stack", 7, (0..10u128).collect());
    let waddr = m.slice("waddr", c, 0, 4);
    let raddr = m.slice("raddr", d, 0, 4);
    let wdata = m.un("wdata", UnOp::AsUnsigned, d);
    m.ram_write(ram, sel, waddr, wdata);
    let rq = m.rom_read("stack_q", ram, raddr);
    out(&mut m, "o_ram", rq);
    // Two instances of one sub-module; the first reads the second's register through a wire
    // driven after both exist (feedback that is legal because it passes a register).
    let sub = std::rc::Rc::new(sub_module());
    let fb = m.wire("feedback", Ty::u(7));
    let first = m.instance("u_first", &sub, &[c, fb]);
    let second = m.instance("u_second", &sub, &[first[0], d]);
    m.drive(fb, second[2]);
    out(&mut m, "o_first", first[0]);
    out(&mut m, "o_second_sel", second[1]);
    m
}

/// A state-machine block: idle → (sel) run → (c < d) hold → done → idle, a counter of the
/// cycles spent in `run`, and a flag compared against the state.
fn state_machine(m: &mut Module, go: fxrt::rtl::Sig, c: fxrt::rtl::Sig, d: fxrt::rtl::Sig) {
    let names: Vec<String> = ["idle", "run", "hold", "done"].iter().map(|s| s.to_string()).collect();
    let b = m.begin_block("ctl", "a small controller", BlockKind::Stage);
    let t = Ty::u(2);
    let state = m.reg("state", t, Some(0));
    m.blocks[b].kind = BlockKind::Fsm { state: state.id, states: names };
    let k: Vec<_> = (0..4).map(|v| m.konst(&format!("to_{v}"), t, v)).collect();
    let from_idle = m.mux("from_idle", go, k[1], k[0]);
    let lt = m.lt("c_lt_d", c, d);
    let from_run = m.mux("from_run", lt, k[2], k[1]);
    let next = m.case("state_next", state, &[(0, from_idle), (1, from_run), (2, k[3])], k[0]);
    m.connect(state, next, None);
    let in_run = m.eq_k("in_run", state, 1);
    let count = m.reg("count", Ty::u(5), Some(0));
    let one = m.konst("one", Ty::u(5), 1);
    let inc = m.add("count_inc", count, one);
    m.connect(count, inc, Some(in_run));
    m.end_block();
    m.output("o_state", state);
    m.output("o_count", count);
}

/// A sub-module with a `case`, a register and a combinational path from input to output.
fn sub_module() -> Module {
    let mut m = Module::new("ops_sub");
    let x = m.input("x", Ty::u(7));
    let y = m.input("y", Ty::u(7));
    let sel = m.slice("sel", x, 0, 2);
    let k = m.konst("k", Ty::u(7), 99);
    let xy = m.bin("xy", BinOp::Xor, x, y);
    let q = m.reg("q", Ty::u(7), Some(3));
    m.connect(q, xy, None);
    let picked = m.case("picked", sel, &[(0, x), (1, y), (3, k)], q);
    m.output("picked", picked);
    let direct = m.bin("direct", BinOp::Add, x, k);
    m.output("direct", direct);
    m.output("q", q);
    m
}

fn stimuli(n: usize) -> Vec<Stimulus> {
    let mut x = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    (0..n)
        .map(|i| {
            let a = (next() % 8192) as i128 - 4096;
            let b = if i % 7 == 0 { a } else { (next() % 8192) as i128 - 4096 };
            let wide = ((next() as i128) << 5) ^ (next() as i128 & 0x1f);
            Stimulus {
                reset: i == 3,
                inputs: vec![a, b, (next() % 128) as i128, (next() % 128) as i128, (next() % 2) as i128, wide],
            }
        })
        .collect()
}

#[test]
fn rust_ghdl_iverilog_and_verilator_agree_on_every_operator() {
    let m = all_ops();
    let t = record(&m, stimuli(400));
    let mut ran = 0;
    for sim in Simulator::ALL {
        if !sim.available() {
            let _ = writeln!(std::io::stderr().lock(), "skipped: {} is not installed", sim.name());
            continue;
        }
        // Kept under target/ so a failure can be inspected (and rerun by hand).
        let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("rtl_cross_{}", sim.name()));
        let (passed, failed) = replay(&m, &t, sim, &dir, &[]).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("{}: {passed} passed, {failed} failed", sim.name());
        assert_eq!((passed, failed), (400, 0), "{}", sim.name());
        ran += 1;
    }
    eprintln!("{ran} HDL simulators ran");
}

#[test]
fn printers_are_deterministic_and_lint_clean() {
    let m = all_ops();
    assert_eq!(vhdl::print(&m), vhdl::print(&all_ops()));
    assert_eq!(verilog::print(&m), verilog::print(&all_ops()));
    let files = design_files(&m, "v");
    let v: String = files.iter().filter(|f| f.0.ends_with(".v")).map(|f| f.1.as_str()).collect();
    let vhd = vhdl::print(&m);
    // A process per block and one for the registers in no block; the states by name.
    for text in ["regs : process (clk)", "s1_regs : process (clk)", "ctl_regs : process (clk)"] {
        assert!(vhd.contains(text), "{text}\n{vhd}");
    }
    // A constant that is a state is written as the state's name, not declared again.
    for text in ["constant st_idle : unsigned(1 downto 0) := \"00\";", "st_done when st_hold,"] {
        assert!(vhd.contains(text), "{text}\n{vhd}");
    }
    assert!(!vhd.contains("constant to_3"), "{vhd}");
    assert!(vhd.contains("-- stage s1: the sum and its tag, registered"), "{vhd}");
    assert!(vhd.contains("from_idle when st_idle,"), "{vhd}");
    for text in [
        "always @(posedge clk) begin : ctl_regs",
        "// state machine ctl: a small controller",
        "(state == st_run) ? from_run :",
    ] {
        assert!(v.contains(text), "{text}\n{v}");
    }
    // Shift registers, not unrolled chains.
    assert!(vhd.contains("tag_late_sr(2 to 5) <= tag_late_sr(1 to 4);"), "{vhd}");
    // Waivers are local: one declaration each, with the reason beside it.
    for (k, line) in v.lines().enumerate().filter(|l| l.1.contains("lint_off")) {
        assert!(line.contains("*/  // "), "line {k}: {line}");
        let on = v.lines().skip(k + 1).position(|l| l.contains("lint_on")).expect("lint_on");
        assert!(on <= 4, "line {k}: a waiver over {on} lines");
    }
    // No `$` in any emitted name: the only `$` are the system functions the printer uses.
    let system = ["$signed", "$unsigned", "$readmemh"].iter().map(|s| v.matches(s).count()).sum::<usize>();
    assert_eq!(v.matches('$').count(), system);
    assert!(v.contains("$readmemh(\"ops_check_table_s.hex\", table_s)"), "memories load from their files");
    if !Simulator::Verilator.available() {
        let _ = writeln!(std::io::stderr().lock(), "skipped: verilator is not installed");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (file, text) in &files {
        std::fs::write(dir.path().join(file), text).unwrap();
    }
    let out = std::process::Command::new("verilator")
        .args(["--lint-only", "-Wall", "--top-module", "ops_check", "ops_sub.v", "ops_check.v"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !text.contains("%Warning"), "{text}");
}

/// `ghdl --synth` takes the VHDL and yosys synthesises the Verilog (shift registers, the
/// state machine, memories), each skipped when not installed.
#[test]
fn both_languages_synthesise() {
    let m = all_ops();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("rtl_cross_synth");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for ext in ["vhd", "v"] {
        for (file, text) in design_files(&m, ext) {
            std::fs::write(dir.join(file), text).unwrap();
        }
    }
    let run = |prog: &str, args: &[&str]| match std::process::Command::new(prog).args(args).current_dir(&dir).output() {
        Ok(o) => assert!(
            o.status.success(),
            "{prog}: {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        ),
        Err(_) => {
            let _ = writeln!(std::io::stderr().lock(), "skipped: {prog} is not installed");
        }
    };
    run("ghdl", &["--synth", "--std=93c", "--out=none", "ops_sub.vhd", "ops_check.vhd", "-e", "ops_check"]);
    run("yosys", &["-q", "-p", "read_verilog ops_sub.v ops_check.v; synth -top ops_check"]);
}
