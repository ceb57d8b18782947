//! The netlist: a module is a list of signals, each with exactly one definition, plus ROMs
//! and instances of other modules. Combinational definitions refer to signals created before
//! them, except through a `Wire`, which is declared first and driven later (feedback, as from
//! a state machine's next-state logic). Registers, ROM reads and RAM writes are the only
//! state. Widths come from `width.rs`.

use super::names;
use super::width::{BinOp, Ty, UnOp, bin_ty, case_arm, eval_bin, eval_concat, eval_mux, eval_un, un_ty};
use std::rc::Rc;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SigId(pub u32);

/// A handle to a signal: its id and type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Sig {
    pub id: SigId,
    pub ty: Ty,
}

#[derive(Clone, Debug, PartialEq, Eq)]
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
    /// A case selection: the arm whose value equals `sel`, else `default`.
    Case {
        sel: SigId,
        arms: Vec<(u128, SigId)>,
        default: SigId,
    },
    /// Concatenation, most significant part first; unsigned.
    Concat(Vec<SigId>),
    /// A named copy of a signal given later with `drive` (forward references).
    Wire(Option<SigId>),
    /// Output `port` of instance `inst` (an index into `Module::instances`).
    InstOut {
        inst: usize,
        port: usize,
    },
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
    /// `src` delayed by `depth` ≥ 1 clock cycles: a shift register with no enable or reset (a
    /// tag riding beside a pipeline). Printed as one array, simulated as `depth` registers.
    DelayLine {
        src: SigId,
        depth: u32,
    },
}

impl Def {
    /// Signals this definition reads in the same clock cycle (its combinational inputs).
    pub fn comb_inputs(&self) -> Vec<SigId> {
        match self {
            Def::Bin(_, a, b) => vec![*a, *b],
            Def::Un(_, a) => vec![*a],
            Def::Mux { sel, t, f } => vec![*sel, *t, *f],
            Def::Case { sel, arms, default } => {
                let mut v = vec![*sel, *default];
                v.extend(arms.iter().map(|a| a.1));
                v
            }
            Def::Concat(parts) => parts.clone(),
            Def::Wire(d) => d.iter().copied().collect(),
            Def::Input
            | Def::Const(_)
            | Def::InstOut { .. }
            | Def::Reg { .. }
            | Def::RomRead { .. }
            | Def::DelayLine { .. } => Vec::new(),
        }
    }

    /// The value of a combinational definition from its operands' bit patterns (in
    /// `comb_inputs` order, with their types) and the result type: the meaning of every
    /// operator, by the rules of `width.rs`.
    pub fn eval(&self, tys: &[Ty], bits: &[u128], tr: Ty) -> u128 {
        match self {
            Def::Bin(op, ..) => eval_bin(*op, tys[0], bits[0], tys[1], bits[1], tr),
            Def::Un(op, _) => eval_un(*op, tys[0], bits[0], tr),
            Def::Mux { .. } => eval_mux(bits[0], bits[1], bits[2]),
            // comb_inputs order: sel, default, arms…
            Def::Case { arms, .. } => case_arm(bits[0], arms.iter().map(|a| a.0)).map_or(bits[1], |k| bits[2 + k]),
            Def::Concat(_) => eval_concat(tys.iter().map(|t| t.width).zip(bits.iter().copied())),
            Def::Wire(_) => bits[0],
            Def::Input
            | Def::Const(_)
            | Def::InstOut { .. }
            | Def::Reg { .. }
            | Def::RomRead { .. }
            | Def::DelayLine { .. } => panic!("not combinational: {self:?}"),
        }
    }

    /// The same definition with every signal reference passed through `f`.
    pub fn map_ids(&self, f: impl Fn(SigId) -> SigId) -> Def {
        match self {
            Def::Input => Def::Input,
            Def::Const(v) => Def::Const(*v),
            Def::Bin(op, a, b) => Def::Bin(*op, f(*a), f(*b)),
            Def::Un(op, a) => Def::Un(*op, f(*a)),
            Def::Mux { sel, t, f: e } => Def::Mux { sel: f(*sel), t: f(*t), f: f(*e) },
            Def::Case { sel, arms, default } => {
                Def::Case { sel: f(*sel), arms: arms.iter().map(|(v, a)| (*v, f(*a))).collect(), default: f(*default) }
            }
            Def::Concat(parts) => Def::Concat(parts.iter().map(|p| f(*p)).collect()),
            Def::Wire(d) => Def::Wire(d.map(&f)),
            Def::InstOut { inst, port } => Def::InstOut { inst: *inst, port: *port },
            Def::Reg { next, enable, reset } => Def::Reg { next: next.map(&f), enable: enable.map(&f), reset: *reset },
            Def::RomRead { rom, addr } => Def::RomRead { rom: *rom, addr: f(*addr) },
            Def::DelayLine { src, depth } => Def::DelayLine { src: f(*src), depth: *depth },
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Signal {
    pub name: String,
    pub ty: Ty,
    pub def: Def,
    /// The block (pipeline stage, state machine) this signal belongs to, an index into
    /// `Module::blocks`: it changes only how the printers lay the design out and comment it.
    pub block: Option<usize>,
}

/// A named part of a module, for the printers: the signals of a pipeline stage or a state
/// machine are printed together, in their own process, under a comment.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Block {
    pub name: String,
    /// One line saying what the block does (printed as a comment).
    pub doc: String,
    pub kind: BlockKind,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BlockKind {
    /// A pipeline stage (its registers load together every clock), or a named stage of a
    /// hand-built core (`Builder::stage`).
    Stage,
    /// A state machine: `state` is its state register; state k (k = its encoding) is named
    /// `states[k]`.
    Fsm { state: SigId, states: Vec<String> },
    /// A register and copies of it, loading what it loads (`Builder::copies`): each drives part of a
    /// fan-out too wide for one net. Printed in a process the synthesizer is told to keep
    /// (`keep`), or it would merge them back.
    Copies,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rom {
    pub name: String,
    pub width: u32,
    /// Initial contents (the whole contents of a ROM).
    pub words: Vec<u128>,
    /// A RAM's synchronous write port: (write enable, address, data). Reads see the old word
    /// in the cycle of a write to the same address (read-first, as block RAM does).
    pub write: Option<(SigId, SigId, SigId)>,
}

/// An instance of another module: `inputs[i]` drives the sub-module's i-th input port; its
/// outputs are this module's `InstOut` signals. Clock and reset are passed through.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Instance {
    pub name: String,
    pub module: Rc<Module>,
    pub inputs: Vec<SigId>,
}

/// Ports printed as one port wider than a signal may be (their parts least significant
/// first): what `bus.rs` builds and the printers show.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bus {
    pub name: String,
    pub input: bool,
    /// Indices into the module's `inputs` (an input bus) or `outputs`, least significant first.
    pub parts: Vec<usize>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Module {
    pub name: String,
    pub signals: Vec<Signal>,
    pub inputs: Vec<SigId>,
    /// Output ports: (port name, driving signal).
    pub outputs: Vec<(String, SigId)>,
    pub roms: Vec<Rom>,
    pub instances: Vec<Instance>,
    pub blocks: Vec<Block>,
    /// Ports printed as one wider port (`bus.rs`).
    pub buses: Vec<Bus>,
    /// The block new signals are put in (`begin_block` … `end_block`).
    pub current_block: Option<usize>,
    /// Every identifier given out so far (signals, ports, memories, instances, buses).
    pub(super) idents: std::collections::BTreeSet<String>,
    /// A module integrators instantiate: its VHDL entity has std_logic / std_logic_vector
    /// ports (a thin entity around `{name}_rtl`, which has the numeric_std ports the other
    /// generated modules use; `emit::vhdl`). Verilog has no port types to change.
    pub std_ports: bool,
}

/// Suffixes the printers derive identifiers with (a shift register's array, its type and loop
/// index; a memory's type): no name may equal another name plus one of them.
const DERIVED: [&str; 4] = ["_sr", "_sr_t", "_i", "_t"];

impl Module {
    pub fn new(name: &str) -> Module {
        Module {
            name: name.to_string(),
            signals: Vec::new(),
            inputs: Vec::new(),
            outputs: Vec::new(),
            roms: Vec::new(),
            instances: Vec::new(),
            blocks: Vec::new(),
            buses: Vec::new(),
            current_block: None,
            // The module's own name is an identifier of its HDL too.
            idents: [name.to_string()].into_iter().collect(),
            std_ports: false,
        }
    }

    /// Opens a block: signals created until `end_block` belong to it. Returns its index.
    pub fn begin_block(&mut self, name: &str, doc: &str, kind: BlockKind) -> usize {
        assert!(self.current_block.is_none(), "{}: block {name} opened inside another", self.name);
        let block = self.add_block(name, doc, kind);
        self.current_block = Some(block);
        block
    }

    /// A block that new signals are not put in (`set_block` puts them there). Returns its index.
    pub fn add_block(&mut self, name: &str, doc: &str, kind: BlockKind) -> usize {
        self.blocks.push(Block { name: names::legal(name), doc: doc.to_string(), kind });
        self.blocks.len() - 1
    }

    pub fn end_block(&mut self) {
        self.current_block = None;
    }

    /// Puts a signal made earlier into a block (a state machine's registers, declared before
    /// the machine that assigns them).
    pub fn set_block(&mut self, id: SigId, block: usize) {
        self.signals[id.0 as usize].block = Some(block);
    }

    pub fn sig(&self, id: SigId) -> &Signal {
        &self.signals[id.0 as usize]
    }

    pub fn handle(&self, id: SigId) -> Sig {
        Sig { id, ty: self.sig(id).ty }
    }

    /// A readable identifier legal in both languages (see `names::legal`), unique among this
    /// module's signals, ports, memories and instance labels.
    fn unique_name(&mut self, base: &str) -> String {
        let s = names::legal(base);
        let idents = &self.idents;
        let taken = |n: &str| {
            idents.contains(n)
                || DERIVED.iter().any(|sfx| {
                    n.strip_suffix(sfx).is_some_and(|b| idents.contains(b)) || idents.contains(&format!("{n}{sfx}"))
                })
        };
        let name = if taken(&s) { (1..).map(|i| format!("{s}_{i}")).find(|n| !taken(n)).unwrap_or(s) } else { s };
        self.idents.insert(name.clone());
        name
    }

    fn push(&mut self, name: &str, ty: Ty, def: Def) -> Sig {
        let name = self.unique_name(name);
        let id = SigId(self.signals.len() as u32);
        self.signals.push(Signal { name, ty, def, block: self.current_block });
        Sig { id, ty }
    }

    /// Renames a signal (the name made legal and unique).
    pub fn rename(&mut self, id: SigId, name: &str) {
        let old = std::mem::take(&mut self.signals[id.0 as usize].name);
        self.idents.remove(&old);
        let n = self.unique_name(name);
        self.signals[id.0 as usize].name = n;
    }

    pub fn input(&mut self, name: &str, ty: Ty) -> Sig {
        assert!(!name.starts_with("tb_"), "{}: port {name}: tb_ names are the testbenches' own", self.name);
        let s = self.push(name, ty, Def::Input);
        self.inputs.push(s.id);
        s
    }

    pub fn konst(&mut self, name: &str, ty: Ty, value: i128) -> Sig {
        assert!(ty.accepts(value), "constant {name} = {value} does not fit {ty:?}");
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
            assert!(ty.accepts(v), "{}: {name}: reset value {v} does not fit", self.name);
            ty.wrap(v)
        });
        self.push(name, ty, Def::Reg { next: None, enable: None, reset })
    }

    pub fn connect(&mut self, reg: Sig, next: Sig, enable: Option<Sig>) {
        let reg_name = self.sig(reg.id).name.clone();
        assert_eq!(reg.ty, next.ty, "{}: register {} input type", self.name, self.sig(reg.id).name);
        if let Some(e) = enable {
            assert_eq!(e.ty, Ty::BIT);
        }
        match &mut self.signals[reg.id.0 as usize].def {
            Def::Reg { next: n @ None, enable: en, .. } => {
                *n = Some(next.id);
                *en = enable.map(|e| e.id);
            }
            _ => panic!("{}: register {reg_name} is driven twice (or is no register)", self.name),
        }
    }

    /// `k` copies of register `reg`, whose input is given (`Builder::copies`), in a block of
    /// their own (`BlockKind::Copies`) with `reg` itself: yosys would merge a register left
    /// outside into a kept copy.
    pub fn copies(&mut self, reg: Sig, k: usize) -> Vec<Sig> {
        let sig = self.sig(reg.id).clone();
        let in_fsm = sig.block.is_some_and(|b| matches!(self.blocks[b].kind, BlockKind::Fsm { .. }));
        assert!(!in_fsm, "{}: {} is a state machine's register", self.name, sig.name);
        let Def::Reg { next: Some(next), enable, reset } = sig.def else {
            panic!("{}: {} is no register with its input given", self.name, sig.name)
        };
        let doc = format!("{} and {k} copies, to split its fan-out", sig.name);
        let block = self.add_block(&format!("{}_copies", sig.name), &doc, BlockKind::Copies);
        self.set_block(reg.id, block);
        let (next, enable) = (self.handle(next), enable.map(|e| self.handle(e)));
        (1..=k)
            .map(|i| {
                let r = self.reg(&format!("{}_c{i}", sig.name), sig.ty, reset.map(|v| sig.ty.value(v)));
                self.connect(r, next, enable);
                self.set_block(r.id, block);
                r
            })
            .collect()
    }

    /// A register that loads `next` every cycle (a pipeline stage).
    pub fn delay(&mut self, name: &str, next: Sig) -> Sig {
        let r = self.reg(name, next.ty, None);
        self.connect(r, next, None);
        r
    }

    /// `src` `depth` clocks later in registers that `rst` clears: a valid bit, so that a reset
    /// leaves nothing in flight (a data shift register may keep its contents).
    pub fn valid_line(&mut self, name: &str, src: Sig, depth: u32) -> Sig {
        let mut prev = src;
        for k in 0..depth {
            let stage = if depth == 1 { name.to_string() } else { format!("{name}_{}", k + 1) };
            let r = self.reg(&stage, src.ty, Some(0));
            self.connect(r, prev, None);
            prev = r;
        }
        prev
    }

    /// `src` delayed by `depth` clock cycles (`src` itself for 0; a register for 1).
    pub fn delay_line(&mut self, name: &str, src: Sig, depth: u32) -> Sig {
        match depth {
            0 => src,
            1 => self.delay(name, src),
            _ => self.push(name, src.ty, Def::DelayLine { src: src.id, depth }),
        }
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
        let bits = crate::bits::rom_addr_bits(self.roms[mem].words.len());
        assert_eq!(we.ty, Ty::BIT, "{}: write enable must be 1 bit", self.name);
        assert_eq!(addr.ty, Ty::u(bits), "{}: RAM {} takes a {bits}-bit address", self.name, self.roms[mem].name);
        assert_eq!(data.ty, Ty::u(self.roms[mem].width), "{}: RAM {} data type", self.name, self.roms[mem].name);
        assert!(self.roms[mem].write.is_none(), "{}: RAM {} has one write port", self.name, self.roms[mem].name);
        // Padded to the power of two the printers use, so every address is a real word.
        let depth = crate::bits::rom_depth(self.roms[mem].words.len());
        self.roms[mem].words.resize(depth, 0);
        self.roms[mem].write = Some((we.id, addr.id, data.id));
    }

    pub fn rom_read(&mut self, name: &str, rom: usize, addr: Sig) -> Sig {
        let w = self.roms[rom].width;
        // The printers pad the ROM to a power of two; the address covers exactly that.
        let bits = crate::bits::rom_addr_bits(self.roms[rom].words.len());
        assert_eq!(
            addr.ty,
            Ty::u(bits),
            "{}: {name}: a ROM of {} words takes a {bits}-bit unsigned address",
            self.name,
            self.roms[rom].words.len()
        );
        self.push(name, Ty::u(w), Def::RomRead { rom, addr: addr.id })
    }

    /// An output port named exactly `name` (made legal): a port name is an interface, so an
    /// internal signal that has the name already is renamed instead.
    pub fn output(&mut self, name: &str, sig: Sig) {
        let name = names::legal(name);
        assert!(!name.starts_with("tb_"), "{}: port {name}: tb_ names are the testbenches' own", self.name);
        let port_taken = self.outputs.iter().any(|o| o.0 == name)
            || self.inputs.iter().any(|&i| self.sig(i).name == name)
            || self.roms.iter().any(|r| r.name == name)
            || self.instances.iter().any(|i| i.name == name);
        assert!(!port_taken, "{}: port {name} is taken", self.name);
        // Internal signals whose name, or a name the printers derive from it, is the port's.
        let clashes: Vec<usize> = (0..self.signals.len())
            .filter(|&k| {
                let n = &self.signals[k].name;
                !matches!(self.signals[k].def, Def::Input)
                    && (*n == name
                        || DERIVED.iter().any(|sfx| format!("{n}{sfx}") == name || format!("{name}{sfx}") == *n))
            })
            .collect();
        self.idents.insert(name.clone());
        for k in clashes {
            let old = std::mem::take(&mut self.signals[k].name);
            self.idents.remove(&old);
            self.signals[k].name = self.unique_name(&format!("{old}_int"));
        }
        self.outputs.push((name, sig.id));
    }

    /// Whether any register here or in an instance has a synchronous reset (the module then
    /// has an `rst` input).
    pub fn has_reset(&self) -> bool {
        self.signals.iter().any(|s| matches!(s.def, Def::Reg { reset: Some(_), .. }))
            || self.instances.iter().any(|i| i.module.has_reset())
    }

    /// Register bits, instances included.
    pub fn register_bits(&self) -> u64 {
        let own: u64 = self
            .signals
            .iter()
            .map(|s| match s.def {
                Def::Reg { .. } => s.ty.width as u64,
                Def::DelayLine { depth, .. } => s.ty.width as u64 * depth as u64,
                _ => 0,
            })
            .sum();
        own + self.instances.iter().map(|i| i.module.register_bits()).sum::<u64>()
    }

    /// Checks that every register and wire is driven; printers and the simulator call it first.
    pub fn check(&self) -> Result<(), String> {
        for s in &self.signals {
            match s.def {
                Def::Reg { next: None, .. } => return Err(format!("{}: register {} has no input", self.name, s.name)),
                Def::Wire(None) => return Err(format!("{}: wire {} is not driven", self.name, s.name)),
                _ => {}
            }
        }
        Ok(())
    }

    /// A signal driven later by `drive`: for feedback that is not through a register.
    pub fn wire(&mut self, name: &str, ty: Ty) -> Sig {
        self.push(name, ty, Def::Wire(None))
    }

    pub fn drive(&mut self, wire: Sig, src: Sig) {
        assert_eq!(wire.ty, src.ty, "{}: wire {} driver type", self.name, self.sig(wire.id).name);
        match &mut self.signals[wire.id.0 as usize].def {
            Def::Wire(d @ None) => *d = Some(src.id),
            _ => panic!("{}: drive on a non-wire or twice", self.name),
        }
    }

    /// `arms[i].1` when `sel` equals `arms[i].0`, else `default` (a `case`/`with select`).
    pub fn case(&mut self, name: &str, sel: Sig, arms: &[(u128, Sig)], default: Sig) -> Sig {
        for (v, a) in arms {
            assert_eq!(a.ty, default.ty, "{}: {name}: case arms must have one type", self.name);
            assert!(sel.ty.width >= 128 || *v >> sel.ty.width == 0, "{}: {name}: arm {v} wider than select", self.name);
        }
        let mut seen: Vec<u128> = arms.iter().map(|a| a.0).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), arms.len(), "{}: {name}: repeated case arm", self.name);
        let arms = arms.iter().map(|(v, a)| (*v, a.id)).collect();
        self.push(name, default.ty, Def::Case { sel: sel.id, arms, default: default.id })
    }

    /// Instantiates `sub` with its inputs driven by `inputs` (in port order); returns its
    /// outputs as signals of this module, named `{label}_{port}`.
    pub fn instance(&mut self, label: &str, sub: &Rc<Module>, inputs: &[Sig]) -> Vec<Sig> {
        assert_eq!(
            inputs.len(),
            sub.inputs.len(),
            "{}: {label}: {} takes {} inputs",
            self.name,
            sub.name,
            sub.inputs.len()
        );
        for (s, &p) in inputs.iter().zip(&sub.inputs) {
            let port = sub.sig(p);
            assert_eq!(s.ty, port.ty, "{}: {label}: input {} of {} type", self.name, port.name, sub.name);
        }
        let name = self.unique_name(label);
        // The component's name is declared in this module's VHDL.
        self.idents.insert(sub.name.clone());
        let inst = self.instances.len();
        self.instances.push(Instance {
            name: name.clone(),
            module: sub.clone(),
            inputs: inputs.iter().map(|s| s.id).collect(),
        });
        (0..sub.outputs.len())
            .map(|port| {
                let (pname, pid) = &sub.outputs[port];
                let ty = sub.sig(*pid).ty;
                self.push(&format!("{name}_{pname}"), ty, Def::InstOut { inst, port })
            })
            .collect()
    }

    /// This module and every module it instantiates, each once, sub-modules before their
    /// users (the order to compile them in). Two different modules may not share a name.
    pub fn hierarchy(&self) -> Vec<&Module> {
        fn visit<'a>(m: &'a Module, out: &mut Vec<&'a Module>) {
            for i in &m.instances {
                visit(&i.module, out);
            }
            match out.iter().find(|x| x.name == m.name) {
                Some(x) => assert!(*x == m, "two different modules are named {}", m.name),
                None => out.push(m),
            }
        }
        let mut out = Vec::new();
        visit(self, &mut out);
        out
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
    pub fn lt(&mut self, name: &str, a: Sig, b: Sig) -> Sig {
        self.bin(name, BinOp::Lt, a, b)
    }
    pub fn and(&mut self, name: &str, a: Sig, b: Sig) -> Sig {
        self.bin(name, BinOp::And, a, b)
    }
    pub fn not(&mut self, name: &str, a: Sig) -> Sig {
        self.un(name, UnOp::Not, a)
    }
    /// `a` equal to the constant `v` (of `a`'s type).
    pub fn eq_k(&mut self, name: &str, a: Sig, v: i128) -> Sig {
        let k = self.konst(&format!("{name}_k"), a.ty, v);
        self.bin(name, BinOp::Eq, a, k)
    }
}
