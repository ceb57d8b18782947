//! The printers' one skeleton. `print` walks a module in a fixed order and asks a `Printer`
//! for the syntax of each part; the two languages implement the same function list and differ
//! only in how they spell things. What is decided about a design — the order of its parts,
//! the grouping by block, the names of states and processes, which signals are read in part
//! only — is decided here, once, for both.
//!
//! The layout: the module header and ports; declarations (components, memories, the state
//! names of each state machine, then the signals, grouped by block under a comment); then,
//! group by group, the combinational assignments and one clocked process for the group's
//! registers, memory reads and shift registers; then the instances and the output ports.
//! Signals in no block come first and share one process (with the RAM writes).

use super::writer::CodeWriter;
use crate::rtl::names;
use crate::rtl::netlist::{BlockKind, Def, Instance, Module, Rom, SigId, Signal};
use crate::rtl::width::{BinOp, Ty, UnOp};
use std::collections::{BTreeMap, BTreeSet};

/// A port of a module; the clock and reset are plain bits (`ty` None).
pub struct Port<'a> {
    pub name: &'a str,
    pub input: bool,
    pub ty: Option<Ty>,
    /// A bus (`rtl::bus`): a plain vector of bits (`std_logic_vector`), not a number.
    pub vector: bool,
    /// Why the port is not read, or read in part only, where that is so (for a lint waiver).
    pub unread: Option<String>,
}

/// A signal read by an expression: its name and type.
#[derive(Clone, Copy)]
pub struct Operand<'a> {
    pub name: &'a str,
    pub ty: Ty,
}

/// How a signal is declared.
pub enum Decl<'a> {
    /// A constant and its value (a literal or a state name).
    Constant(&'a str),
    /// Clocked storage (a register, a memory read) and its power-up value.
    Register(&'a str),
    /// A register of a `Copies` block: as `Register`, and synthesis must not merge it.
    KeptRegister(&'a str),
    /// A shift register of `depth` words powering up at zero; the signal is its last word.
    Shift { depth: u32 },
    /// Driven by a continuous assignment.
    Net,
    /// Driven by a combinational process (a `case`).
    Selected,
}

/// The syntax of one language, in the order `print` asks for it.
pub trait Printer {
    /// The comment leader.
    fn leader(&self) -> &'static str;
    /// A literal of type `ty`, usable in any expression.
    fn literal(&self, ty: Ty, v: u128) -> String;
    /// A `case` choice for a selector of type `ty`.
    fn choice(&self, ty: Ty, v: u128) -> String;
    /// Everything up to the declarations: libraries, the entity or module, its ports.
    fn open(&self, w: &mut CodeWriter, m: &Module, ports: &[Port]);
    /// The declaration of a module instantiated here, where the language needs one.
    fn component(&self, w: &mut CodeWriter, sub: &Module, ports: &[Port]);
    /// A memory with its contents.
    fn memory(&self, w: &mut CodeWriter, m: &Module, rom: &Rom);
    /// A state machine's state names and encodings (type `ty`); `all_used` is false when the
    /// logic compares against or loads only some of them.
    fn states(&self, w: &mut CodeWriter, ty: Ty, states: &[(String, u128)], all_used: bool);
    /// A signal's declaration; `unread` says why it is not read or read in part only.
    fn declare(&self, w: &mut CodeWriter, sig: &Signal, decl: Decl, unread: Option<&str>);
    /// Between the declarations and the statements.
    fn begin_body(&self, w: &mut CodeWriter);
    /// A continuous assignment.
    fn assign(&self, w: &mut CodeWriter, target: &str, expr: &str);
    /// The expression of a binary operator; `ty` is the result's type.
    fn bin(&self, op: BinOp, a: Operand, b: Operand, ty: Ty) -> String;
    /// The expression of a unary operator; `ty` is the result's type.
    fn un(&self, op: UnOp, a: Operand, ty: Ty) -> String;
    /// `sel ? t : f`.
    fn mux(&self, sel: &str, t: &str, f: &str) -> String;
    /// A concatenation, most significant part first (unsigned).
    fn concat(&self, parts: &[Operand]) -> String;
    /// Bits [lsb, lsb + width) of bus port `bus`: an assignment target, or else an unsigned
    /// expression.
    fn bus_bits(&self, bus: &str, lsb: u32, width: u32, target: bool) -> String;
    /// An unsigned value as the bits of a bus.
    fn to_bus(&self, a: Operand) -> String;
    /// The last word of the shift register of signal `name`.
    fn tap(&self, name: &str, depth: u32) -> String;
    /// A case selection: `arms` are (choice, value).
    fn case(&self, w: &mut CodeWriter, target: &str, sel: &str, arms: &[(String, &str)], default: &str);
    /// An instance with its port map (formal, actual).
    fn instance(&self, w: &mut CodeWriter, inst: &Instance, map: &[(&str, &str)]);
    /// The attribute declarations `KeptRegister` declarations use (once, before them).
    fn keep_attributes(&self, w: &mut CodeWriter);
    /// The start of a clocked process named `label`; `keep`: its registers are copies that
    /// synthesis must not merge.
    fn begin_clocked(&self, w: &mut CodeWriter, label: &str, keep: bool);
    /// A register load: the synchronous reset value first, then the enable.
    fn load(&self, w: &mut CodeWriter, target: &str, next: &str, enable: Option<&str>, reset: Option<&str>);
    /// A synchronous memory read.
    fn read(&self, w: &mut CodeWriter, target: &str, mem: &str, addr: &str);
    /// A RAM's synchronous write.
    fn write(&self, w: &mut CodeWriter, mem: &str, we: &str, addr: &str, data: &str);
    /// One step of the shift register of signal `name`, fed by `src`.
    fn shift(&self, w: &mut CodeWriter, name: &str, src: &str, depth: u32);
    /// The end of the clocked process `label`.
    fn end_clocked(&self, w: &mut CodeWriter, label: &str);
    /// The end of the module.
    fn close(&self, w: &mut CodeWriter, m: &Module);
}

/// The module `m` in the language of `p`.
pub fn print(m: &Module, p: &impl Printer) -> String {
    m.check().unwrap_or_else(|e| panic!("{e}"));
    let cx = Context::new(m);
    let mut w = CodeWriter::new(p.leader());
    w.comment(format!("{}: generated by fxrt {}; do not edit.", m.name, env!("CARGO_PKG_VERSION")));
    p.open(&mut w, m, &cx.ports(m));
    w.indented(|w| declarations(m, &cx, p, w));
    p.begin_body(&mut w);
    w.indented(|w| {
        for (k, &id) in m.inputs.iter().enumerate() {
            if let Some((bus, lsb)) = m.bus_part(true, k) {
                p.assign(w, cx.name(id), &p.bus_bits(&bus.name, lsb, m.sig(id).ty.width, false));
            }
        }
        for group in cx.groups.iter().filter(|g| !g.is_empty(m)) {
            w.blank();
            cx.heading(w, group.block);
            for &id in &group.signals {
                statement(m, &cx, p, w, id);
            }
            clocked(m, &cx, p, w, group);
        }
        for (k, inst) in m.instances.iter().enumerate() {
            w.blank();
            let sub = &inst.module;
            let mut map: Vec<(&str, &str)> = vec![("clk", "clk")];
            if sub.has_reset() {
                map.push(("rst", "rst"));
            }
            map.extend(sub.inputs.iter().zip(&inst.inputs).map(|(f, a)| (sub.sig(*f).name.as_str(), cx.name(*a))));
            for s in &m.signals {
                if let Def::InstOut { inst: i, port } = s.def
                    && i == k
                {
                    map.push((sub.outputs[port].0.as_str(), s.name.as_str()));
                }
            }
            p.instance(w, inst, &map);
        }
        w.blank();
        for (k, (port, id)) in m.outputs.iter().enumerate() {
            match m.bus_part(false, k) {
                Some((bus, lsb)) => {
                    let bits = p.bus_bits(&bus.name, lsb, m.sig(*id).ty.width, true);
                    p.assign(w, &bits, &p.to_bus(Operand { name: cx.name(*id), ty: m.sig(*id).ty }));
                }
                None => p.assign(w, port, cx.name(*id)),
            }
        }
    });
    p.close(&mut w, m);
    w.finish()
}

fn declarations(m: &Module, cx: &Context, p: &impl Printer, w: &mut CodeWriter) {
    let mut declared: Vec<&str> = Vec::new();
    for inst in &m.instances {
        if !declared.contains(&inst.module.name.as_str()) {
            declared.push(&inst.module.name);
            p.component(w, &inst.module, &cx.ports(&inst.module));
        }
    }
    for r in &m.roms {
        w.blank();
        p.memory(w, m, r);
    }
    // State names come first: constants and power-up values below may be written with them.
    for (b, names) in &cx.states {
        let BlockKind::Fsm { state, .. } = &m.blocks[*b].kind else { continue };
        w.blank();
        w.comment(format!("states of {}", m.blocks[*b].name));
        let states: Vec<(String, u128)> = names.iter().enumerate().map(|(v, n)| (n.clone(), v as u128)).collect();
        let all_used = (0..names.len()).all(|v| cx.used_states.contains(&(*b, v as u128)));
        p.states(w, m.sig(*state).ty, &states, all_used);
    }
    if m.blocks.iter().any(|b| b.kind == BlockKind::Copies) {
        p.keep_attributes(w);
    }
    for group in cx.groups.iter().filter(|g| !g.is_empty(m)) {
        w.blank();
        cx.heading(w, group.block);
        let kept = cx.is_copies(group);
        for &id in &group.signals {
            let sig = m.sig(id);
            let power_up = |v: u128| cx.value(p, id, v);
            let unread = cx.unread(id);
            let unread = unread.as_deref();
            match &sig.def {
                // A part of a bus is a signal assigned from the bus port.
                Def::Input if m.is_bus_input(id) => p.declare(w, sig, Decl::Net, unread),
                Def::Input => {}
                // A state constant is written as the state's name.
                Def::Const(v) if cx.state_name(id, *v).is_some() => {}
                Def::Const(v) => p.declare(w, sig, Decl::Constant(&power_up(*v)), unread),
                // Registers power up at their reset value (0 without one), as in the simulator.
                Def::Reg { reset, .. } => {
                    let v = power_up(reset.unwrap_or(0));
                    p.declare(w, sig, if kept { Decl::KeptRegister(&v) } else { Decl::Register(&v) }, unread)
                }
                Def::RomRead { .. } => p.declare(w, sig, Decl::Register(&p.literal(sig.ty, 0)), unread),
                Def::DelayLine { depth, .. } => p.declare(w, sig, Decl::Shift { depth: *depth }, unread),
                Def::Case { .. } => p.declare(w, sig, Decl::Selected, unread),
                Def::Bin(..) | Def::Un(..) | Def::Mux { .. } | Def::Concat(_) | Def::Wire(_) | Def::InstOut { .. } => {
                    p.declare(w, sig, Decl::Net, unread)
                }
            }
        }
    }
}

/// The combinational statement that drives signal `id`, if any.
fn statement(m: &Module, cx: &Context, p: &impl Printer, w: &mut CodeWriter, id: SigId) {
    let sig = m.sig(id);
    let op = |id: SigId| Operand { name: cx.name(id), ty: m.sig(id).ty };
    let expr = match &sig.def {
        Def::Input | Def::Const(_) | Def::Reg { .. } | Def::RomRead { .. } | Def::InstOut { .. } => return,
        Def::Wire(d) => cx.name(d.expect("checked")).to_string(),
        Def::DelayLine { depth, .. } => p.tap(&sig.name, *depth),
        Def::Bin(o, a, b) => p.bin(*o, op(*a), op(*b), sig.ty),
        Def::Un(o, a) => p.un(*o, op(*a), sig.ty),
        Def::Mux { sel, t, f } => p.mux(cx.name(*sel), cx.name(*t), cx.name(*f)),
        Def::Concat(parts) => p.concat(&parts.iter().map(|&x| op(x)).collect::<Vec<_>>()),
        Def::Case { sel, arms, default } => {
            let choices: Vec<(String, &str)> =
                arms.iter().map(|(v, a)| (cx.choice(p, *sel, *v), cx.name(*a))).collect();
            p.case(w, &sig.name, cx.name(*sel), &choices, cx.name(*default));
            return;
        }
    };
    p.assign(w, &sig.name, &expr);
}

/// The clocked process of a group: its registers, memory reads and shift registers (and, for
/// the signals in no block, the RAM writes).
fn clocked(m: &Module, cx: &Context, p: &impl Printer, w: &mut CodeWriter, group: &Group) {
    let writes = group.writes(m);
    let state: Vec<SigId> = group
        .signals
        .iter()
        .copied()
        .filter(|&id| matches!(m.sig(id).def, Def::Reg { .. } | Def::RomRead { .. } | Def::DelayLine { .. }))
        .collect();
    if state.is_empty() && writes.is_empty() {
        return;
    }
    w.blank();
    p.begin_clocked(w, &group.label, cx.is_copies(group));
    for r in writes {
        let (we, addr, data) = r.write.expect("filtered");
        p.write(w, &r.name, cx.name(we), cx.name(addr), cx.name(data));
    }
    for id in state {
        let sig = m.sig(id);
        match &sig.def {
            Def::Reg { next, enable, reset } => {
                let reset = reset.map(|v| cx.value(p, id, v));
                p.load(w, &sig.name, cx.name(next.expect("checked")), enable.map(|e| cx.name(e)), reset.as_deref());
            }
            Def::RomRead { rom, addr } => p.read(w, &sig.name, &m.roms[*rom].name, cx.name(*addr)),
            Def::DelayLine { src, depth } => p.shift(w, &sig.name, cx.name(*src), *depth),
            Def::Input
            | Def::Const(_)
            | Def::Bin(..)
            | Def::Un(..)
            | Def::Mux { .. }
            | Def::Case { .. }
            | Def::Concat(_)
            | Def::Wire(_)
            | Def::InstOut { .. } => unreachable!("filtered to clocked signals"),
        }
    }
    p.end_clocked(w, &group.label);
}

/// The signals of one block (or of none), in netlist order, and the label of their process.
struct Group {
    block: Option<usize>,
    signals: Vec<SigId>,
    label: String,
}

impl Group {
    /// The RAM writes in the group's process: those of every RAM, in the group of no block.
    fn writes<'m>(&self, m: &'m Module) -> Vec<&'m Rom> {
        let mine = self.block.is_none();
        m.roms.iter().filter(|r| mine && r.write.is_some()).collect()
    }

    fn is_empty(&self, m: &Module) -> bool {
        self.signals.is_empty() && self.writes(m).is_empty()
    }
}

/// What the walk decides about a module before printing it.
struct Context<'m> {
    m: &'m Module,
    groups: Vec<Group>,
    /// The state names of each state machine, by block index.
    states: BTreeMap<usize, Vec<String>>,
    /// Signals that hold a state of a machine (its state register, the constants it is loaded
    /// from or compared with), and the machine's block.
    state_of: BTreeMap<SigId, usize>,
    /// (block, state) pairs some statement names.
    used_states: BTreeSet<(usize, u128)>,
    /// The bits of each signal that something reads (a mask).
    read: Vec<u128>,
}

impl<'m> Context<'m> {
    fn new(m: &'m Module) -> Context<'m> {
        let mut taken = taken_names(m);
        let mut fresh = |base: &str| {
            let base = names::legal(base);
            let name = std::iter::once(base.clone())
                .chain((1..).map(|i| format!("{base}_{i}")))
                .find(|n| !taken.contains(n))
                .expect("a free name");
            taken.insert(name.clone());
            name
        };
        let mut groups = vec![Group { block: None, signals: Vec::new(), label: fresh("regs") }];
        groups.extend(m.blocks.iter().enumerate().map(|(b, block)| Group {
            block: Some(b),
            signals: Vec::new(),
            label: fresh(&format!("{}_regs", block.name)),
        }));
        for (i, s) in m.signals.iter().enumerate() {
            groups[s.block.map_or(0, |b| b + 1)].signals.push(SigId(i as u32));
        }
        let mut states = BTreeMap::new();
        for (b, block) in m.blocks.iter().enumerate() {
            if let BlockKind::Fsm { states: names, .. } = &block.kind {
                states.insert(b, names.iter().map(|n| fresh(&format!("st_{n}"))).collect());
            }
        }
        let mut cx =
            Context { m, groups, states, state_of: state_signals(m), used_states: BTreeSet::new(), read: reads(m) };
        cx.used_states = cx.state_uses();
        cx
    }

    /// How signal `id` is written: its name, or for a constant that is a state of a machine
    /// the state's name (such constants are not declared).
    fn name(&self, id: SigId) -> &str {
        match self.m.sig(id).def {
            Def::Const(v) => self.state_name(id, v).unwrap_or(&self.m.sig(id).name),
            _ => &self.m.sig(id).name,
        }
    }

    /// The comment over a block's declarations and statements.
    fn heading(&self, w: &mut CodeWriter, block: Option<usize>) {
        let Some(b) = block else {
            if !self.m.blocks.is_empty() {
                w.comment("not in a stage or state machine");
            }
            return;
        };
        let block = &self.m.blocks[b];
        let kind = match block.kind {
            BlockKind::Stage => "stage",
            BlockKind::Fsm { .. } => "state machine",
            BlockKind::Copies => "register copies",
        };
        w.comment(format!("{kind} {}: {}", block.name, block.doc));
    }

    /// Whether `group` is a block of register copies.
    fn is_copies(&self, group: &Group) -> bool {
        group.block.is_some_and(|b| self.m.blocks[b].kind == BlockKind::Copies)
    }

    /// The name of state `v` when signal `id` holds a state of a machine that names it.
    fn state_name(&self, id: SigId, v: u128) -> Option<&str> {
        let b = self.state_of.get(&id)?;
        self.states.get(b)?.get(usize::try_from(v).ok()?).map(|s| s.as_str())
    }

    /// Value `v` of signal `id`: a state name or a literal.
    fn value(&self, p: &impl Printer, id: SigId, v: u128) -> String {
        self.state_name(id, v).map_or_else(|| p.literal(self.m.sig(id).ty, v), str::to_string)
    }

    /// A case choice `v` for selector `sel`: a state name or a literal choice.
    fn choice(&self, p: &impl Printer, sel: SigId, v: u128) -> String {
        self.state_name(sel, v).map_or_else(|| p.choice(self.m.sig(sel).ty, v), str::to_string)
    }

    /// Every (machine, state) that `value` or `choice` will print by name.
    fn state_uses(&self) -> BTreeSet<(usize, u128)> {
        let mut used = BTreeSet::new();
        for (i, s) in self.m.signals.iter().enumerate() {
            let id = SigId(i as u32);
            let values: Vec<(SigId, u128)> = match &s.def {
                Def::Const(v) => vec![(id, *v)],
                Def::Reg { reset, .. } => vec![(id, reset.unwrap_or(0))],
                Def::Case { sel, arms, .. } => arms.iter().map(|a| (*sel, a.0)).collect(),
                Def::Input
                | Def::Bin(..)
                | Def::Un(..)
                | Def::Mux { .. }
                | Def::Concat(_)
                | Def::Wire(_)
                | Def::InstOut { .. }
                | Def::RomRead { .. }
                | Def::DelayLine { .. } => Vec::new(),
            };
            for (id, v) in values {
                if self.state_name(id, v).is_some() {
                    used.insert((self.state_of[&id], v));
                }
            }
        }
        used
    }

    /// Why signal `id` is not read, or read in part only (None when all of it is read).
    fn unread(&self, id: SigId) -> Option<String> {
        let read = self.read[id.0 as usize];
        unread_text(&(0..self.m.sig(id).ty.width).map(|b| (read >> b) & 1 == 1).collect::<Vec<_>>())
    }

    /// The ports of `m` (this module or one it instantiates) with what of them is not read.
    fn ports<'a>(&self, m: &'a Module) -> Vec<Port<'a>> {
        let own = std::ptr::eq(m, self.m);
        let clocked =
            m.signals.iter().any(|s| matches!(s.def, Def::Reg { .. } | Def::RomRead { .. } | Def::DelayLine { .. }))
                || m.roms.iter().any(|r| r.write.is_some())
                || !m.instances.is_empty();
        let clk_unread = (own && !clocked).then(|| "no register here: the clock is not read".to_string());
        let mut ports = vec![Port { name: "clk", input: true, ty: None, vector: false, unread: clk_unread }];
        if m.has_reset() {
            ports.push(Port { name: "rst", input: true, ty: None, vector: false, unread: None });
        }
        assert!(own || m.buses.is_empty(), "{}: a module with buses is a top level, not instantiated", m.name);
        for port in m.printed_ports() {
            let unread = match (own && port.input, port.bus) {
                (false, _) => None,
                (true, None) => {
                    self.unread(m.inputs[m.inputs.iter().position(|&i| m.sig(i).name == port.name).expect("an input")])
                }
                (true, Some(bus)) => {
                    // The bits of the bus that its parts' readers read.
                    let bits: Vec<bool> = bus
                        .parts
                        .iter()
                        .flat_map(|&k| {
                            let id = m.inputs[k];
                            (0..m.sig(id).ty.width).map(move |b| (self.read[id.0 as usize] >> b) & 1 == 1)
                        })
                        .collect();
                    unread_text(&bits)
                }
            };
            ports.push(Port {
                name: port.name,
                input: port.input,
                ty: Some(port.ty),
                vector: port.bus.is_some(),
                unread,
            });
        }
        ports
    }
}

/// Why a port or signal whose bits (least significant first) are read where `read` is true is
/// not read, or read in part only (None when all of it is read).
fn unread_text(read: &[bool]) -> Option<String> {
    if read.iter().all(|&r| r) {
        return None;
    }
    if !read.iter().any(|&r| r) {
        return Some("not read".into());
    }
    let mut ranges = Vec::new();
    let mut b = read.len();
    while b > 0 {
        b -= 1;
        if read[b] {
            let hi = b;
            while b > 0 && read[b - 1] {
                b -= 1;
            }
            ranges.push(if hi == b { format!("{b}") } else { format!("{hi}:{b}") });
        }
    }
    Some(format!("only bits {} are read", ranges.join(", ")))
}

/// Every identifier the printers use in `m` before the walk names states and processes.
fn taken_names(m: &Module) -> BTreeSet<String> {
    let mut taken: BTreeSet<String> = ["clk", "rst", "rtl"].iter().map(|s| s.to_string()).collect();
    taken.insert(m.name.clone());
    for s in &m.signals {
        taken.insert(s.name.clone());
        // A shift register's array, its type and its loop index.
        for suffix in ["_sr", "_sr_t", "_i"] {
            taken.insert(format!("{}{suffix}", s.name));
        }
    }
    for r in &m.roms {
        taken.insert(r.name.clone());
        taken.insert(format!("{}_t", r.name));
    }
    taken.extend(m.outputs.iter().map(|o| o.0.clone()));
    taken.extend(m.buses.iter().map(|b| b.name.clone()));
    for i in &m.instances {
        taken.insert(i.name.clone());
        taken.insert(i.module.name.clone());
    }
    taken
}

/// The signals that hold a state of a machine: its state register, the constants loaded into
/// it (through muxes, cases and wires) and the constants it is compared with.
fn state_signals(m: &Module) -> BTreeMap<SigId, usize> {
    let mut out = BTreeMap::new();
    for (b, block) in m.blocks.iter().enumerate() {
        let BlockKind::Fsm { state, .. } = &block.kind else { continue };
        let ty = m.sig(*state).ty;
        out.entry(*state).or_insert(b);
        let mut todo: Vec<SigId> = Vec::new();
        let mut seen = BTreeSet::new();
        if let Def::Reg { next: Some(n), .. } = m.sig(*state).def {
            todo.push(n);
        }
        for s in &m.signals {
            if let Def::Bin(BinOp::Eq | BinOp::Ne, x, y) = s.def {
                if x == *state {
                    todo.push(y);
                } else if y == *state {
                    todo.push(x);
                }
            }
        }
        while let Some(id) = todo.pop() {
            if !seen.insert(id) {
                continue;
            }
            match &m.sig(id).def {
                Def::Const(_) if m.sig(id).ty == ty => {
                    out.entry(id).or_insert(b);
                }
                Def::Mux { t, f, .. } => todo.extend([*t, *f]),
                Def::Case { arms, default, .. } => {
                    todo.push(*default);
                    todo.extend(arms.iter().map(|a| a.1));
                }
                Def::Wire(d) => todo.extend(*d),
                Def::Const(_)
                | Def::Input
                | Def::Bin(..)
                | Def::Un(..)
                | Def::Concat(_)
                | Def::InstOut { .. }
                | Def::Reg { .. }
                | Def::RomRead { .. }
                | Def::DelayLine { .. } => {}
            }
        }
    }
    out
}

/// The bits of each signal that the printed design reads, as a mask: a slice reads its bits, a
/// truncation its low bits, everything else the whole signal.
fn reads(m: &Module) -> Vec<u128> {
    let mut read = vec![0u128; m.signals.len()];
    let whole = |id: SigId| m.sig(id).ty.mask();
    let all = |read: &mut Vec<u128>, ids: &[SigId]| ids.iter().for_each(|&i| read[i.0 as usize] |= whole(i));
    for s in &m.signals {
        match &s.def {
            Def::Un(op, a) => {
                let bits = match *op {
                    UnOp::Slice { lsb, width } => Ty::u(width).mask() << lsb,
                    UnOp::Resize(w) if w < m.sig(*a).ty.width => Ty::u(w).mask(),
                    UnOp::Resize(_)
                    | UnOp::Not
                    | UnOp::Neg
                    | UnOp::Shl(_)
                    | UnOp::Shr(_)
                    | UnOp::AsSigned
                    | UnOp::AsUnsigned => whole(*a),
                };
                read[a.0 as usize] |= bits;
            }
            Def::Reg { next, enable, .. } => {
                all(&mut read, &[*next, *enable].into_iter().flatten().collect::<Vec<_>>())
            }
            Def::RomRead { addr, .. } => all(&mut read, &[*addr]),
            Def::DelayLine { src, .. } => all(&mut read, &[*src]),
            Def::Input
            | Def::Const(_)
            | Def::Bin(..)
            | Def::Mux { .. }
            | Def::Case { .. }
            | Def::Concat(_)
            | Def::Wire(_)
            | Def::InstOut { .. } => all(&mut read, &s.def.comb_inputs()),
        }
    }
    for r in &m.roms {
        if let Some((we, addr, data)) = r.write {
            all(&mut read, &[we, addr, data]);
        }
    }
    for i in &m.instances {
        all(&mut read, &i.inputs);
    }
    all(&mut read, &m.outputs.iter().map(|o| o.1).collect::<Vec<_>>());
    read
}
