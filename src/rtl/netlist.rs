//! The netlist: a module is a list of signals in SSA form (every signal has exactly one
//! definition, and combinational definitions only refer to signals created before them), plus
//! ROMs. Registers and ROM reads are the only state. Widths come from `width.rs`.

use super::width::{BinOp, Ty, UnOp, bin_ty, un_ty};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct SigId(pub u32);

/// A handle to a signal: its id and type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sig {
    pub id: SigId,
    pub ty: Ty,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub enum Def {
    Input,
    Const(u128),
    Bin(BinOp, SigId, SigId),
    Un(UnOp, SigId),
    /// `sel ? t : f` with a 1-bit `sel`.
    Mux {
        sel: SigId,
        t: SigId,
        f: SigId,
    },
    /// Concatenation, most significant part first; unsigned.
    Concat(Vec<SigId>),
    /// A register clocked by the module clock. `reset` is a synchronous reset value (driven
    /// by the module's `rst` input); without `enable` it loads every cycle.
    Reg {
        next: Option<SigId>,
        enable: Option<SigId>,
        reset: Option<u128>,
    },
    /// A synchronous ROM read (block RAM): the word at `addr`, one cycle later.
    RomRead {
        rom: usize,
        addr: SigId,
    },
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Signal {
    pub name: String,
    pub ty: Ty,
    pub def: Def,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Rom {
    pub name: String,
    pub width: u32,
    /// Initial contents (the whole contents of a ROM).
    pub words: Vec<u128>,
    /// A RAM's synchronous write port: (write enable, address, data). Reads see the old word
    /// in the cycle of a write to the same address (read-first, as block RAM does).
    pub write: Option<(SigId, SigId, SigId)>,
}

#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Module {
    pub name: String,
    pub signals: Vec<Signal>,
    pub inputs: Vec<SigId>,
    /// Output ports: (port name, driving signal).
    pub outputs: Vec<(String, SigId)>,
    pub roms: Vec<Rom>,
}

/// Names no emitted identifier may take (VHDL-93 and Verilog-2001 keywords, and the ports the
/// printers add themselves).
const RESERVED: &[&str] = &[
    "abs",
    "access",
    "after",
    "alias",
    "all",
    "and",
    "architecture",
    "array",
    "assert",
    "assign",
    "attribute",
    "begin",
    "block",
    "body",
    "buffer",
    "bus",
    "case",
    "component",
    "configuration",
    "constant",
    "default",
    "disconnect",
    "downto",
    "else",
    "elsif",
    "end",
    "entity",
    "exit",
    "file",
    "for",
    "function",
    "generate",
    "generic",
    "group",
    "guarded",
    "if",
    "impure",
    "in",
    "inertial",
    "initial",
    "inout",
    "input",
    "integer",
    "is",
    "label",
    "library",
    "linkage",
    "literal",
    "loop",
    "map",
    "mod",
    "module",
    "nand",
    "new",
    "next",
    "nor",
    "not",
    "null",
    "of",
    "on",
    "open",
    "or",
    "others",
    "out",
    "output",
    "package",
    "parameter",
    "port",
    "postponed",
    "procedure",
    "process",
    "pure",
    "range",
    "record",
    "reg",
    "register",
    "reject",
    "rem",
    "report",
    "return",
    "rol",
    "ror",
    "select",
    "severity",
    "signal",
    "shared",
    "signed",
    "sla",
    "sll",
    "sra",
    "srl",
    "subtype",
    "then",
    "to",
    "transport",
    "type",
    "unaffected",
    "units",
    "until",
    "unsigned",
    "use",
    "variable",
    "wait",
    "when",
    "while",
    "wire",
    "with",
    "xnor",
    "xor",
    "always",
    "endmodule",
    "integer",
    "clk",
    "rst",
    "time",
    "event",
    "force",
    "release",
    "real",
    "tri",
    "edge",
    "posedge",
    "negedge",
    "table",
    "endtable",
    "primitive",
    "endprimitive",
    "specify",
    "endspecify",
    "task",
    "endtask",
    "endfunction",
    "endcase",
    "endgenerate",
    "casex",
    "casez",
    "defparam",
    "deassign",
    "disable",
    "forever",
    "fork",
    "join",
    "genvar",
    "localparam",
    "repeat",
    "supply0",
    "supply1",
    "tri0",
    "tri1",
    "triand",
    "trior",
    "trireg",
    "wand",
    "wor",
    "buf",
    "bufif0",
    "bufif1",
    "notif0",
    "notif1",
    "pullup",
    "pulldown",
    "cmos",
    "nmos",
    "pmos",
    "rcmos",
    "rnmos",
    "rpmos",
    "tran",
    "scalared",
    "vectored",
    "small",
    "medium",
    "large",
    "strong0",
    "strong1",
    "weak0",
    "weak1",
    "highz0",
    "highz1",
    "pull0",
    "pull1",
    "macromodule",
];

impl Module {
    pub fn new(name: &str) -> Module {
        Module {
            name: name.to_string(),
            signals: Vec::new(),
            inputs: Vec::new(),
            outputs: Vec::new(),
            roms: Vec::new(),
        }
    }

    pub fn sig(&self, id: SigId) -> &Signal {
        &self.signals[id.0 as usize]
    }

    pub fn handle(&self, id: SigId) -> Sig {
        Sig { id, ty: self.sig(id).ty }
    }

    /// A readable, unique identifier legal in both languages: lower case, [a-z0-9_], starting
    /// with a letter, no double or trailing underscore, not a keyword.
    fn unique_name(&self, base: &str) -> String {
        let mut s: String =
            base.to_ascii_lowercase().chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
        while s.contains("__") {
            s = s.replace("__", "_");
        }
        let mut s = s.trim_matches('_').to_string();
        if s.is_empty() || !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
            s = format!("s_{s}");
        }
        if RESERVED.contains(&s.as_str()) {
            s.push_str("_s");
        }
        let taken = |n: &str| {
            self.signals.iter().any(|x| x.name == n)
                || self.outputs.iter().any(|x| x.0 == n)
                || self.roms.iter().any(|x| x.name == n)
        };
        if !taken(&s) {
            return s;
        }
        (1..).map(|i| format!("{s}_{i}")).find(|n| !taken(n)).unwrap_or(s)
    }

    fn push(&mut self, name: &str, ty: Ty, def: Def) -> Sig {
        let name = self.unique_name(name);
        let id = SigId(self.signals.len() as u32);
        self.signals.push(Signal { name, ty, def });
        Sig { id, ty }
    }

    pub fn input(&mut self, name: &str, ty: Ty) -> Sig {
        let s = self.push(name, ty, Def::Input);
        self.inputs.push(s.id);
        s
    }

    pub fn konst(&mut self, name: &str, ty: Ty, value: i128) -> Sig {
        assert!(ty.fits(value), "constant {name} = {value} does not fit {ty:?}");
        self.push(name, ty, Def::Const(ty.wrap(value)))
    }

    pub fn bin(&mut self, name: &str, op: BinOp, a: Sig, b: Sig) -> Sig {
        let ty = bin_ty(op, a.ty, b.ty).unwrap_or_else(|e| panic!("{}: {name}: {e}", self.name));
        self.push(name, ty, Def::Bin(op, a.id, b.id))
    }

    pub fn un(&mut self, name: &str, op: UnOp, a: Sig) -> Sig {
        let ty = un_ty(op, a.ty).unwrap_or_else(|e| panic!("{}: {name}: {e}", self.name));
        self.push(name, ty, Def::Un(op, a.id))
    }

    pub fn mux(&mut self, name: &str, sel: Sig, t: Sig, f: Sig) -> Sig {
        assert_eq!(sel.ty, Ty::BIT, "{}: {name}: mux select must be 1 bit", self.name);
        assert_eq!(t.ty, f.ty, "{}: {name}: mux arms must have one type", self.name);
        self.push(name, t.ty, Def::Mux { sel: sel.id, t: t.id, f: f.id })
    }

    pub fn concat(&mut self, name: &str, parts: &[Sig]) -> Sig {
        let w: u32 = parts.iter().map(|p| p.ty.width).sum();
        assert!(w <= super::width::MAX_WIDTH, "{}: {name}: concat of {w} bits", self.name);
        self.push(name, Ty::u(w), Def::Concat(parts.iter().map(|p| p.id).collect()))
    }

    /// Declares a register; its input is given later with `connect`.
    pub fn reg(&mut self, name: &str, ty: Ty, reset: Option<i128>) -> Sig {
        let reset = reset.map(|v| {
            assert!(ty.fits(v), "{}: {name}: reset value {v} does not fit", self.name);
            ty.wrap(v)
        });
        self.push(name, ty, Def::Reg { next: None, enable: None, reset })
    }

    pub fn connect(&mut self, reg: Sig, next: Sig, enable: Option<Sig>) {
        assert_eq!(reg.ty, next.ty, "{}: register {} input type", self.name, self.sig(reg.id).name);
        if let Some(e) = enable {
            assert_eq!(e.ty, Ty::BIT);
        }
        match &mut self.signals[reg.id.0 as usize].def {
            Def::Reg { next: n @ None, enable: en, .. } => {
                *n = Some(next.id);
                *en = enable.map(|e| e.id);
            }
            _ => panic!("{}: connect on a non-register or twice", self.name),
        }
    }

    /// A register that loads `next` every cycle (a pipeline stage).
    pub fn delay(&mut self, name: &str, next: Sig) -> Sig {
        let r = self.reg(name, next.ty, None);
        self.connect(r, next, None);
        r
    }

    pub fn rom(&mut self, name: &str, width: u32, words: Vec<u128>) -> usize {
        let name = self.unique_name(name);
        assert!(!words.is_empty());
        self.roms.push(Rom { name, width, words, write: None });
        self.roms.len() - 1
    }

    /// A RAM: a ROM with a synchronous write port (`ram_write`), read with `rom_read`.
    pub fn ram(&mut self, name: &str, width: u32, init: Vec<u128>) -> usize {
        self.rom(name, width, init)
    }

    pub fn ram_write(&mut self, mem: usize, we: Sig, addr: Sig, data: Sig) {
        let bits = super::emit::rom_addr_bits(self.roms[mem].words.len());
        assert_eq!(we.ty, Ty::BIT, "{}: write enable must be 1 bit", self.name);
        assert_eq!(addr.ty, Ty::u(bits), "{}: RAM {} takes a {bits}-bit address", self.name, self.roms[mem].name);
        assert_eq!(data.ty, Ty::u(self.roms[mem].width), "{}: RAM {} data type", self.name, self.roms[mem].name);
        assert!(self.roms[mem].write.is_none(), "{}: RAM {} has one write port", self.name, self.roms[mem].name);
        // Padded to the power of two the printers use, so every address is a real word.
        let depth = super::emit::rom_depth(self.roms[mem].words.len());
        self.roms[mem].words.resize(depth, 0);
        self.roms[mem].write = Some((we.id, addr.id, data.id));
    }

    pub fn rom_read(&mut self, name: &str, rom: usize, addr: Sig) -> Sig {
        let w = self.roms[rom].width;
        // The printers pad the ROM to a power of two; the address covers exactly that.
        let bits = super::emit::rom_addr_bits(self.roms[rom].words.len());
        assert_eq!(
            addr.ty,
            Ty::u(bits),
            "{}: {name}: a ROM of {} words takes a {bits}-bit unsigned address",
            self.name,
            self.roms[rom].words.len()
        );
        self.push(name, Ty::u(w), Def::RomRead { rom, addr: addr.id })
    }

    pub fn output(&mut self, name: &str, sig: Sig) {
        let name = self.unique_name(name);
        self.outputs.push((name, sig.id));
    }

    /// Whether any register has a synchronous reset (the module then has an `rst` input).
    pub fn has_reset(&self) -> bool {
        self.signals.iter().any(|s| matches!(s.def, Def::Reg { reset: Some(_), .. }))
    }

    /// Checks that every register is connected; printers and the simulator call it first.
    pub fn check(&self) -> Result<(), String> {
        for s in &self.signals {
            if let Def::Reg { next: None, .. } = s.def {
                return Err(format!("{}: register {} has no input", self.name, s.name));
            }
        }
        Ok(())
    }

    // Short forms used by the cores.
    pub fn add(&mut self, name: &str, a: Sig, b: Sig) -> Sig {
        self.bin(name, BinOp::Add, a, b)
    }
    pub fn sub(&mut self, name: &str, a: Sig, b: Sig) -> Sig {
        self.bin(name, BinOp::Sub, a, b)
    }
    pub fn mul(&mut self, name: &str, a: Sig, b: Sig) -> Sig {
        self.bin(name, BinOp::Mul, a, b)
    }
    pub fn resize(&mut self, name: &str, a: Sig, width: u32) -> Sig {
        if a.ty.width == width { a } else { self.un(name, UnOp::Resize(width), a) }
    }
    pub fn shr(&mut self, name: &str, a: Sig, k: u32) -> Sig {
        if k == 0 { a } else { self.un(name, UnOp::Shr(k), a) }
    }
    pub fn shl(&mut self, name: &str, a: Sig, k: u32) -> Sig {
        if k == 0 { a } else { self.un(name, UnOp::Shl(k), a) }
    }
    pub fn slice(&mut self, name: &str, a: Sig, lsb: u32, width: u32) -> Sig {
        self.un(name, UnOp::Slice { lsb, width }, a)
    }
    pub fn bit(&mut self, name: &str, a: Sig, i: u32) -> Sig {
        self.slice(name, a, i, 1)
    }
}
