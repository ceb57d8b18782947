//! Golden files: a small design with a pipeline stage, a state machine, register copies and
//! delay lines, printed
//! in both languages and compared with `tests/golden/`. After an intended change to the
//! printers, rewrite them with `UPDATE_GOLDEN=1 cargo test --test printers_golden` and review
//! the diff.

use fxrt::rtl::emit::{verilog, vhdl};
use fxrt::rtl::netlist::BlockKind;
use fxrt::rtl::{Module, Ty};

fn demo() -> Module {
    let mut m = Module::new("golden_demo");
    let x = m.input("x", Ty::s(8));
    let go = m.input("go", Ty::BIT);
    // A stage: the square of x, of which only the high byte is kept.
    m.begin_block("square", "x squared, high byte", BlockKind::Stage);
    let sq = m.mul("sq", x, x);
    let sq_r = m.delay("sq_r", sq);
    let high = m.slice("high", sq_r, 8, 8);
    m.end_block();
    // A state machine: idle, then busy for as long as `go` stays high, then done for a cycle;
    // `spare` is named but never reached (its name gets a lint waiver in Verilog).
    let b = m.begin_block("ctl", "waits for go", BlockKind::Stage);
    let t = Ty::u(2);
    let state = m.reg("state", t, Some(0));
    let states = ["idle", "busy", "done", "spare"].iter().map(|s| s.to_string()).collect();
    m.blocks[b].kind = BlockKind::Fsm { state: state.id, states };
    let idle = m.konst("go_idle", t, 0);
    let busy = m.konst("go_busy", t, 1);
    let done = m.konst("go_done", t, 2);
    let from_idle = m.mux("from_idle", go, busy, idle);
    let from_busy = m.mux("from_busy", go, busy, done);
    let next = m.case("state_next", state, &[(0, from_idle), (1, from_busy)], idle);
    m.connect(state, next, None);
    let is_done = m.eq_k("is_done", state, 2);
    m.end_block();
    // Two copies of the square's register, which synthesis must not merge back into it.
    let copies = m.copies(sq_r, 2);
    let go_late = m.delay_line("go_late", go, 3);
    // A delay line deeper than 64: Verilator does not unroll a longer loop and refuses a
    // delayed assignment to an array inside one (BLKLOOPINIT), so the printers write no loop.
    let go_later = m.delay_line("go_later", go, 70);
    m.output("o_high", high);
    m.output("o_done", is_done);
    m.output("o_go_late", go_late);
    m.output("o_go_later", go_later);
    let both = m.concat("both_copies", &copies);
    m.output("o_sq_copies", both);
    m
}

#[test]
fn printers_match_their_golden_files() {
    let m = demo();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden");
    for (file, text) in [("golden_demo.vhd", vhdl::print(&m)), ("golden_demo.v", verilog::print(&m))] {
        let path = dir.join(file);
        if std::env::var_os("UPDATE_GOLDEN").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let want = std::fs::read_to_string(&path).unwrap_or_default();
        assert!(text == want, "{file} differs from tests/golden (UPDATE_GOLDEN=1 rewrites it):\n{text}");
    }
    match std::process::Command::new("verilator")
        .args(["--lint-only", "-Wall", "golden_demo.v"])
        .current_dir(&dir)
        .output()
    {
        Ok(o) => {
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(o.status.success() && !err.contains("%Warning"), "verilator lint: {err}");
        }
        Err(_) => eprintln!("skipped: verilator is not installed"),
    }
}
