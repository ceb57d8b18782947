//! VHDL-93 printer: `ieee.numeric_std` only, one entity and architecture per module,
//! concurrent assignments for the combinational signals, `with … select` for a `case`, and a
//! single-process clocked `process (clk)` per pipeline stage or state machine (and one for the
//! registers in no block): the style XST and `ghdl --synth` map cleanly.

use super::bit_string;
use super::walk::{Decl, Operand, Port, Printer};
use super::writer::CodeWriter;
use crate::rtl::netlist::{Instance, Module, Rom, Signal};
use crate::rtl::width::{BinOp, Ty, UnOp};

/// The VHDL printer.
pub struct Vhdl;

/// The VHDL of module `m`.
pub fn print(m: &Module) -> String {
    super::walk::print(m, &Vhdl)
}

/// The numeric_std type of `t`'s signedness.
fn kind(t: Ty) -> &'static str {
    if t.signed { "signed" } else { "unsigned" }
}

fn vtype(t: Ty) -> String {
    format!("{}({} downto 0)", kind(t), t.width - 1)
}

/// The port clause of an entity or component.
fn port_clause(w: &mut CodeWriter, ports: &[Port]) {
    w.nest("port (", ");", |w| {
        for (k, p) in ports.iter().enumerate() {
            let dir = if p.input { "in" } else { "out" };
            let ty = p.ty.map_or_else(|| "std_logic".to_string(), vtype);
            let sep = if k + 1 < ports.len() { ";" } else { "" };
            w.line(format!("{} : {dir} {ty}{sep}", p.name));
        }
    });
}

impl Printer for Vhdl {
    fn leader(&self) -> &'static str {
        "--"
    }

    /// A qualified bit string: valid for any width, in any expression.
    fn literal(&self, ty: Ty, v: u128) -> String {
        format!("{}'(\"{}\")", kind(ty), bit_string(v, ty.width))
    }

    fn choice(&self, ty: Ty, v: u128) -> String {
        format!("\"{}\"", bit_string(v, ty.width))
    }

    fn open(&self, w: &mut CodeWriter, m: &Module, ports: &[Port]) {
        for lib in ["library ieee;", "use ieee.std_logic_1164.all;", "use ieee.numeric_std.all;"] {
            w.line(lib);
        }
        w.blank();
        w.nest(format!("entity {} is", m.name), format!("end entity {};", m.name), |w| port_clause(w, ports));
        w.blank();
        w.line(format!("architecture rtl of {} is", m.name));
    }

    /// A component declaration per instantiated entity (XST-friendly component binding).
    fn component(&self, w: &mut CodeWriter, sub: &Module, ports: &[Port]) {
        w.nest(format!("component {} is", sub.name), "end component;", |w| port_clause(w, ports));
    }

    /// A RAM is a signal (written in a clocked process), a ROM a constant.
    fn memory(&self, w: &mut CodeWriter, _m: &Module, r: &Rom) {
        let depth = super::rom_depth(r.words.len());
        w.line(format!("type {}_t is array (0 to {}) of unsigned({} downto 0);", r.name, depth - 1, r.width - 1));
        let kind = if r.write.is_some() { "signal" } else { "constant" };
        w.nest(format!("{kind} {} : {}_t := (", r.name, r.name), "", |w| {
            for (i, word) in r.words.iter().enumerate() {
                w.line(format!("{i} => \"{}\",", bit_string(*word, r.width)));
            }
            w.line("others => (others => '0'));");
        });
    }

    fn states(&self, w: &mut CodeWriter, ty: Ty, states: &[(String, u128)], _all_used: bool) {
        for (name, v) in states {
            w.line(format!("constant {name} : {} := \"{}\";", vtype(ty), bit_string(*v, ty.width)));
        }
    }

    fn declare(&self, w: &mut CodeWriter, sig: &Signal, decl: Decl, _unread: Option<&str>) {
        let (n, t) = (&sig.name, vtype(sig.ty));
        match decl {
            Decl::Constant(v) => w.line(format!("constant {n} : {t} := {v};")),
            Decl::Register(v) => w.line(format!("signal {n} : {t} := {v};")),
            Decl::Shift { depth } => {
                w.line(format!("type {n}_sr_t is array (1 to {depth}) of {t};"));
                w.line(format!("signal {n}_sr : {n}_sr_t := (others => (others => '0'));"));
                w.line(format!("signal {n} : {t};"));
            }
            Decl::Net | Decl::Selected => w.line(format!("signal {n} : {t};")),
        }
    }

    fn begin_body(&self, w: &mut CodeWriter) {
        w.line("begin");
    }

    fn assign(&self, w: &mut CodeWriter, target: &str, expr: &str) {
        w.line(format!("{target} <= {expr};"));
    }

    fn bin(&self, op: BinOp, a: Operand, b: Operand, _ty: Ty) -> String {
        let (a, b) = (a.name, b.name);
        let word = match op {
            BinOp::And => "and",
            BinOp::Or => "or",
            BinOp::Xor => "xor",
            BinOp::Eq => "=",
            BinOp::Ne => "/=",
            // The rest are spelled as in Verilog (and C).
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Lt | BinOp::Le => super::symbol(op),
        };
        match op {
            // A comparison gives a one-bit vector.
            BinOp::Eq | BinOp::Ne | BinOp::Lt | BinOp::Le => format!("\"1\" when {a} {word} {b} else \"0\""),
            BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::And | BinOp::Or | BinOp::Xor => format!("{a} {word} {b}"),
        }
    }

    fn un(&self, op: UnOp, a: Operand, ty: Ty) -> String {
        let (ta, a) = (a.ty, a.name);
        match op {
            UnOp::Not => format!("not {a}"),
            UnOp::Neg if ta.signed => format!("-{a}"),
            UnOp::Neg => format!("(not {a}) + 1"),
            UnOp::Shl(k) => format!("shift_left({a}, {k})"),
            UnOp::Shr(k) => format!("shift_right({a}, {k})"),
            UnOp::Slice { lsb, width } => format!("unsigned({a}({} downto {lsb}))", lsb + width - 1),
            UnOp::Resize(w) if w > ta.width => format!("resize({a}, {w})"),
            // Shrinking keeps the low bits (numeric_std's resize would keep the sign).
            UnOp::Resize(w) => format!("{a}({} downto 0)", w - 1),
            UnOp::AsSigned | UnOp::AsUnsigned => format!("{}({a})", kind(ty)),
        }
    }

    fn mux(&self, sel: &str, t: &str, f: &str) -> String {
        format!("{t} when {sel} = \"1\" else {f}")
    }

    /// Qualified: `&` is overloaded for every array type.
    fn concat(&self, parts: &[Operand]) -> String {
        let p: Vec<String> = parts.iter().map(|p| format!("std_logic_vector({})", p.name)).collect();
        format!("unsigned(std_logic_vector'({}))", p.join(" & "))
    }

    fn tap(&self, name: &str, depth: u32) -> String {
        format!("{name}_sr({depth})")
    }

    /// A selected signal assignment: VHDL-93's concurrent `case`.
    fn case(&self, w: &mut CodeWriter, target: &str, sel: &str, arms: &[(String, &str)], default: &str) {
        w.nest(format!("with {sel} select"), "", |w| {
            w.nest(format!("{target} <="), "", |w| {
                arms.iter().for_each(|(choice, v)| w.line(format!("{v} when {choice},")));
                w.line(format!("{default} when others;"));
            });
        });
    }

    fn instance(&self, w: &mut CodeWriter, inst: &Instance, map: &[(&str, &str)]) {
        w.nest(format!("{} : {}", inst.name, inst.module.name), "", |w| {
            w.nest("port map (", ");", |w| {
                for (k, (formal, actual)) in map.iter().enumerate() {
                    w.line(format!("{formal} => {actual}{}", if k + 1 < map.len() { "," } else { "" }));
                }
            });
        });
    }

    fn begin_clocked(&self, w: &mut CodeWriter, label: &str) {
        w.line(format!("{label} : process (clk)"));
        w.line("begin");
        w.open("");
        w.open("if rising_edge(clk) then");
    }

    fn load(&self, w: &mut CodeWriter, target: &str, next: &str, enable: Option<&str>, reset: Option<&str>) {
        let assign = format!("{target} <= {next};");
        match (reset, enable) {
            (None, None) => w.line(assign),
            (None, Some(e)) => w.nest(format!("if {e} = \"1\" then"), "end if;", |w| w.line(assign)),
            (Some(r), enable) => {
                w.nest("if rst = '1' then", "", |w| w.line(format!("{target} <= {r};")));
                match enable {
                    Some(e) => w.nest(format!("elsif {e} = \"1\" then"), "end if;", |w| w.line(assign)),
                    None => w.nest("else", "end if;", |w| w.line(assign)),
                }
            }
        }
    }

    fn read(&self, w: &mut CodeWriter, target: &str, mem: &str, addr: &str) {
        w.line(format!("{target} <= {mem}(to_integer({addr}));"));
    }

    fn write(&self, w: &mut CodeWriter, mem: &str, we: &str, addr: &str, data: &str) {
        w.nest(format!("if {we} = \"1\" then"), "end if;", |w| w.line(format!("{mem}(to_integer({addr})) <= {data};")));
    }

    fn shift(&self, w: &mut CodeWriter, name: &str, src: &str, depth: u32) {
        w.line(format!("{name}_sr(2 to {depth}) <= {name}_sr(1 to {});", depth - 1));
        w.line(format!("{name}_sr(1) <= {src};"));
    }

    fn end_clocked(&self, w: &mut CodeWriter, label: &str) {
        w.close("end if;");
        w.close("");
        w.line(format!("end process {label};"));
    }

    fn close(&self, w: &mut CodeWriter, _m: &Module) {
        w.line("end architecture rtl;");
    }
}
