//! Verilog-2001 printer (Icarus `-g2005`, Verilator `-Wall`): one module per netlist, a
//! continuous assignment per combinational signal (a `case` too, as a chain of `?:`), and an
//! `always @(posedge clk)` block per pipeline stage or state machine (and one for the
//! registers in no block). Operands are extended explicitly wherever Verilog's
//! context-determined widths would otherwise decide (products), so the width lint stays quiet;
//! a declaration that is not read, or read in part only, carries its own commented waiver.

use super::walk::{Decl, Operand, Port, Printer};
use super::writer::CodeWriter;
use super::{hex_string, rom_depth};
use crate::rtl::netlist::{Instance, Module, Rom, Signal};
use crate::rtl::width::{BinOp, Ty, UnOp};

/// The Verilog printer.
pub struct Verilog;

/// The Verilog of module `m`.
pub fn print(m: &Module) -> String {
    super::walk::print(m, &Verilog)
}

fn decl(t: Ty) -> String {
    format!("{}[{}:0]", if t.signed { "signed " } else { "" }, t.width - 1)
}

/// `a` extended to `w` bits by its own signedness, as an expression of that signedness.
fn extend(a: &str, t: Ty, w: u32) -> String {
    if w == t.width {
        return a.to_string();
    }
    let fill = if t.signed {
        format!("{{{}{{{a}[{}]}}}}", w - t.width, t.width - 1)
    } else {
        format!("{{{}{{1'b0}}}}", w - t.width)
    };
    if t.signed { format!("$signed({{{fill}, {a}}})") } else { format!("{{{fill}, {a}}}") }
}

/// Lines wrapped in a Verilator waiver for `rule` when `why` is given, with `why` beside it.
fn waived(w: &mut CodeWriter, rule: &str, why: Option<&str>, body: impl FnOnce(&mut CodeWriter)) {
    match why {
        None => body(w),
        Some(why) => {
            w.commented(format!("/* verilator lint_off {rule} */"), Some(why));
            body(w);
            w.line(format!("/* verilator lint_on {rule} */"));
        }
    }
}

/// RAMs of at most this many words are asked for in LUTs (`ram_style`).
pub const DISTRIBUTED_WORDS: usize = 128;

/// The `$readmemh` file of memory `rom` of module `m`.
pub fn mem_file(m: &Module, rom: &str) -> String {
    format!("{}_{rom}.hex", m.name)
}

/// The contents of every memory of `m` as `$readmemh` files, padded with zero words to the
/// printed depth: (file name, text).
pub fn mem_files(m: &Module) -> Vec<(String, String)> {
    m.roms
        .iter()
        .map(|r| {
            let mut text = String::with_capacity(rom_depth(r.words.len()) * (r.width as usize / 4 + 2));
            for k in 0..rom_depth(r.words.len()) {
                text.push_str(&hex_string(r.words.get(k).copied().unwrap_or(0), r.width));
                text.push('\n');
            }
            (mem_file(m, &r.name), text)
        })
        .collect()
}

impl Printer for Verilog {
    fn leader(&self) -> &'static str {
        "//"
    }

    fn literal(&self, ty: Ty, v: u128) -> String {
        format!("{}'{}h{}", ty.width, if ty.signed { "s" } else { "" }, hex_string(v, ty.width))
    }

    fn choice(&self, ty: Ty, v: u128) -> String {
        self.literal(Ty::u(ty.width), v)
    }

    fn open(&self, w: &mut CodeWriter, m: &Module, ports: &[Port]) {
        w.line("`default_nettype none");
        w.nest(format!("module {} (", m.name), ");", |w| {
            for (k, p) in ports.iter().enumerate() {
                let dir = if p.input { "input" } else { "output" };
                let ty = p.ty.map_or_else(String::new, |t| format!(" {}", decl(t)));
                let sep = if k + 1 < ports.len() { "," } else { "" };
                waived(w, "UNUSEDSIGNAL", p.unread.as_deref(), |w| w.line(format!("{dir} wire{ty} {}{sep}", p.name)));
            }
        });
    }

    /// Verilog finds a module by its name: nothing to declare.
    fn component(&self, _w: &mut CodeWriter, _sub: &Module, _ports: &[Port]) {}

    /// Contents load with `$readmemh` from a file beside the module (`mem_files`): a statement
    /// per word makes large ROMs slow to parse (yosys: minutes per 10,000 words).
    fn memory(&self, w: &mut CodeWriter, m: &Module, r: &Rom) {
        // A small RAM (the per-slot memories and queues, `DISTRIBUTED_WORDS` words or fewer) is
        // asked for in LUTs: yosys otherwise spends a block on each of them (8 DP16KDs the
        // teapot's core did not have to spare); Xilinx tools read the same attribute.
        let depth = rom_depth(r.words.len());
        let style =
            if r.write.is_some() && depth <= DISTRIBUTED_WORDS { "(* ram_style = \"distributed\" *) " } else { "" };
        w.line(format!("{style}reg [{}:0] {} [0:{}];", r.width - 1, r.name, depth - 1));
        w.line(format!("initial $readmemh(\"{}\", {});", mem_file(m, &r.name), r.name));
    }

    fn states(&self, w: &mut CodeWriter, ty: Ty, states: &[(String, u128)], all_used: bool) {
        let why = (!all_used).then_some("every state is named, also those no logic names");
        waived(w, "UNUSEDPARAM", why, |w| {
            for (name, v) in states {
                w.line(format!("localparam {} {name} = {};", decl(ty), self.literal(ty, *v)));
            }
        });
    }

    fn declare(&self, w: &mut CodeWriter, sig: &Signal, d: Decl, unread: Option<&str>) {
        let (n, t) = (&sig.name, decl(sig.ty));
        waived(w, "UNUSEDSIGNAL", unread, |w| match d {
            Decl::Constant(v) => w.line(format!("wire {t} {n} = {v};")),
            Decl::Register(v) | Decl::KeptRegister(v) => w.line(format!("reg {t} {n} = {v};")),
            Decl::Shift { depth } => {
                // Registers, not a memory: yosys would say so with a warning otherwise.
                w.line(format!("(* mem2reg *) reg {t} {n}_sr [1:{depth}];"));
                w.line(format!("integer {n}_i;"));
                let zero = self.literal(sig.ty, 0);
                w.line(format!("initial for ({n}_i = 1; {n}_i <= {depth}; {n}_i = {n}_i + 1) {n}_sr[{n}_i] = {zero};"));
                w.line(format!("wire {t} {n};"));
            }
            // A case is a continuous assignment too (see `case`), so its target is a `wire`.
            Decl::Net | Decl::Selected => w.line(format!("wire {t} {n};")),
        });
    }

    fn begin_body(&self, _w: &mut CodeWriter) {}

    fn assign(&self, w: &mut CodeWriter, target: &str, expr: &str) {
        w.line(format!("assign {target} = {expr};"));
    }

    /// Products extend both operands to the result's width first.
    fn bin(&self, op: BinOp, a: Operand, b: Operand, ty: Ty) -> String {
        match op {
            BinOp::Mul => format!("{} * {}", extend(a.name, a.ty, ty.width), extend(b.name, b.ty, ty.width)),
            BinOp::Add
            | BinOp::Sub
            | BinOp::And
            | BinOp::Or
            | BinOp::Xor
            | BinOp::Eq
            | BinOp::Ne
            | BinOp::Lt
            | BinOp::Le => format!("{} {} {}", a.name, super::symbol(op), b.name),
        }
    }

    fn un(&self, op: UnOp, a: Operand, _ty: Ty) -> String {
        let (ta, a) = (a.ty, a.name);
        match op {
            UnOp::Not => format!("~{a}"),
            UnOp::Neg => format!("-{a}"),
            UnOp::Shl(k) => format!("{a} <<< {k}"),
            UnOp::Shr(k) if ta.signed => format!("{a} >>> {k}"),
            UnOp::Shr(k) => format!("{a} >> {k}"),
            UnOp::Slice { lsb, width: 1 } => format!("{a}[{lsb}]"),
            UnOp::Slice { lsb, width } => format!("{a}[{}:{lsb}]", lsb + width - 1),
            UnOp::Resize(w) if w > ta.width => extend(a, ta, w),
            UnOp::Resize(w) if ta.signed => format!("$signed({a}[{}:0])", w - 1),
            UnOp::Resize(w) => format!("{a}[{}:0]", w - 1),
            UnOp::AsSigned => format!("$signed({a})"),
            UnOp::AsUnsigned => format!("$unsigned({a})"),
        }
    }

    fn mux(&self, sel: &str, t: &str, f: &str) -> String {
        format!("{sel} ? {t} : {f}")
    }

    fn concat(&self, parts: &[Operand]) -> String {
        format!("{{{}}}", parts.iter().map(|p| p.name).collect::<Vec<_>>().join(", "))
    }

    fn bus_bits(&self, bus: &str, lsb: u32, width: u32, _target: bool) -> String {
        format!("{bus}[{}:{lsb}]", lsb + width - 1)
    }

    fn to_bus(&self, a: Operand) -> String {
        a.name.to_string()
    }

    fn tap(&self, name: &str, depth: u32) -> String {
        format!("{name}_sr[{depth}]")
    }

    /// A chain of conditional operators in one continuous assignment, not an `always @*`
    /// block: under SystemVerilog rules (Icarus `-g2012`, as cocotb runs it) an `always @*`
    /// whose inputs are registers with initial values never runs at time 0 and leaves its
    /// target X until an input changes; a continuous assignment is evaluated at time 0 under
    /// both rule sets.
    fn case(&self, w: &mut CodeWriter, target: &str, sel: &str, arms: &[(String, &str)], default: &str) {
        w.line(format!("assign {target} ="));
        w.indented(|w| {
            arms.iter().for_each(|(choice, v)| w.line(format!("({sel} == {choice}) ? {v} :")));
            w.line(format!("{default};"));
        });
    }

    fn instance(&self, w: &mut CodeWriter, inst: &Instance, map: &[(&str, &str)]) {
        w.nest(format!("{} {} (", inst.module.name, inst.name), ");", |w| {
            let last = map.len().saturating_sub(1);
            map.iter()
                .enumerate()
                .for_each(|(k, (f, a))| w.line(format!(".{f}({a}){}", if k < last { "," } else { "" })));
        });
    }

    fn keep_attributes(&self, _w: &mut CodeWriter) {}

    /// Yosys puts a process's attributes on the flip-flops it makes of it (`keep` on the
    /// register itself would keep only the net); `opt_merge` leaves kept cells apart.
    fn begin_clocked(&self, w: &mut CodeWriter, label: &str, keep: bool) {
        let keep = if keep { "(* keep *) " } else { "" };
        w.open(format!("{keep}always @(posedge clk) begin : {label}"));
    }

    fn load(&self, w: &mut CodeWriter, target: &str, next: &str, enable: Option<&str>, reset: Option<&str>) {
        let guard = match (reset, enable) {
            (Some(r), _) => {
                w.line(format!("if (rst) {target} <= {r};"));
                "else "
            }
            (None, _) => "",
        };
        match enable {
            Some(e) => w.line(format!("{guard}if ({e}) {target} <= {next};")),
            None => w.line(format!("{guard}{target} <= {next};")),
        }
    }

    fn read(&self, w: &mut CodeWriter, target: &str, mem: &str, addr: &str) {
        w.line(format!("{target} <= {mem}[{addr}];"));
    }

    fn write(&self, w: &mut CodeWriter, mem: &str, we: &str, addr: &str, data: &str) {
        w.line(format!("if ({we}) {mem}[{addr}] <= {data};"));
    }

    fn shift(&self, w: &mut CodeWriter, name: &str, src: &str, depth: u32) {
        // One statement per register, no loop: Verilator unrolls at most 64 iterations and
        // refuses a delayed assignment to an array inside a loop it keeps (BLKLOOPINIT), which
        // a pipeline at n = 40 reached (a 71-deep tag line).
        for i in (2..=depth).rev() {
            w.line(format!("{name}_sr[{i}] <= {name}_sr[{}];", i - 1));
        }
        w.line(format!("{name}_sr[1] <= {src};"));
    }

    fn end_clocked(&self, w: &mut CodeWriter, _label: &str) {
        w.close("end");
    }

    fn close(&self, w: &mut CodeWriter, _m: &Module) {
        w.line("endmodule");
        w.line("`default_nettype wire");
    }
}
