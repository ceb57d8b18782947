//! Flattening for the simulator: a module and its instances become one list of value slots.
//! Instance ports, wires and sub-module inputs are aliases, not copies: each resolves to the
//! slot of the signal that really drives it. Combinational definitions are then ordered by a
//! depth-first topological sort, so feedback through wires and instances evaluates correctly
//! and a combinational loop is reported instead of simulated wrongly.

use super::netlist::{Def, Module, SigId};
use super::width::Ty;

/// A memory of the flat design; addresses and write-port signals are slots.
#[derive(Clone, Debug)]
pub struct FlatMem {
    pub words: Vec<u128>,
    pub write: Option<(usize, usize, usize)>,
}

#[derive(Clone, Debug)]
pub struct Flat {
    /// Type and definition of each slot; `SigId`s inside are slots, `RomRead::rom` indexes
    /// `mems`. No `Wire` or `InstOut` remains; `Input` is only the top module's.
    pub tys: Vec<Ty>,
    pub defs: Vec<Def>,
    /// Slots with a combinational definition, in an order that evaluates each after its inputs.
    pub comb_order: Vec<usize>,
    pub mems: Vec<FlatMem>,
    /// Slot of each signal of the top module, by `SigId`.
    pub top: Vec<usize>,
    /// Every named signal of the hierarchy as `instance/…/signal` with its slot, for probing
    /// internal state in a debugger or a reproducer (`Sim::probe`); top-level names have no
    /// prefix.
    pub names: Vec<(String, usize)>,
}

enum Global {
    /// Stands for another global signal (ports, wires).
    Alias(usize),
    /// A definition whose references are global signal numbers (and `rom` a global memory).
    Real(Def, Ty),
}

struct Builder {
    signals: Vec<Global>,
    /// Hierarchical name of each global signal that came from a module's signal list.
    names: Vec<(String, usize)>,
    mems: Vec<(Vec<u128>, Option<(usize, usize, usize)>)>,
}

impl Builder {
    /// Adds `m`'s signals, then its instances' (recursively); `drivers` are the global
    /// signals driving `m`'s inputs (None for the top module). Returns `m`'s first number.
    fn add(&mut self, m: &Module, drivers: Option<&[usize]>, prefix: &str) -> usize {
        let base = self.signals.len();
        self.names.extend(m.signals.iter().enumerate().map(|(k, s)| (format!("{prefix}{}", s.name), base + k)));
        let g = |id: SigId| SigId((base + id.0 as usize) as u32);
        self.signals.extend(m.signals.iter().map(|_| Global::Alias(usize::MAX)));
        let mem_base = self.mems.len();
        for r in &m.roms {
            let write = r.write.map(|(we, a, d)| (g(we).0 as usize, g(a).0 as usize, g(d).0 as usize));
            self.mems.push((r.words.clone(), write));
        }
        let sub_bases: Vec<usize> = m
            .instances
            .iter()
            .map(|inst| {
                let d: Vec<usize> = inst.inputs.iter().map(|&i| g(i).0 as usize).collect();
                self.add(&inst.module, Some(&d), &format!("{prefix}{}/", inst.name))
            })
            .collect();
        for (k, s) in m.signals.iter().enumerate() {
            self.signals[base + k] = match &s.def {
                Def::Input => match drivers {
                    Some(d) => {
                        let pos = m.inputs.iter().position(|&i| i.0 as usize == k).expect("an input is a port");
                        Global::Alias(d[pos])
                    }
                    None => Global::Real(Def::Input, s.ty),
                },
                Def::InstOut { inst, port } => {
                    let sub = &m.instances[*inst].module;
                    Global::Alias(sub_bases[*inst] + sub.outputs[*port].1.0 as usize)
                }
                Def::Wire(d) => Global::Alias(g(d.expect("checked")).0 as usize),
                Def::RomRead { rom, addr } => Global::Real(Def::RomRead { rom: mem_base + rom, addr: g(*addr) }, s.ty),
                // A chain of plain registers: depth − 1 new signals, the last one this signal.
                Def::DelayLine { src, depth } => {
                    let mut prev = g(*src);
                    for _ in 1..*depth {
                        let reg = Def::Reg { next: Some(prev), enable: None, reset: None };
                        self.signals.push(Global::Real(reg, s.ty));
                        prev = SigId((self.signals.len() - 1) as u32);
                    }
                    Global::Real(Def::Reg { next: Some(prev), enable: None, reset: None }, s.ty)
                }
                other => Global::Real(other.map_ids(g), s.ty),
            };
        }
        base
    }

    /// The signal an alias chain ends at.
    fn root(&self, mut i: usize) -> usize {
        for _ in 0..=self.signals.len() {
            match self.signals[i] {
                Global::Alias(j) => i = j,
                Global::Real(..) => return i,
            }
        }
        panic!("a loop of wires and ports with no driver");
    }
}

pub fn flatten(m: &Module) -> Flat {
    fn check_all(m: &Module) {
        m.check().unwrap_or_else(|e| panic!("{e}"));
        m.instances.iter().for_each(|i| check_all(&i.module));
    }
    check_all(m);
    let mut b = Builder { signals: Vec::new(), names: Vec::new(), mems: Vec::new() };
    b.add(m, None, "");
    // Slots for real signals, in global order; aliases share their root's slot.
    let mut slot = vec![usize::MAX; b.signals.len()];
    let mut count = 0;
    for (i, s) in b.signals.iter().enumerate() {
        if let Global::Real(..) = s {
            slot[i] = count;
            count += 1;
        }
    }
    for i in 0..b.signals.len() {
        if slot[i] == usize::MAX {
            slot[i] = slot[b.root(i)];
        }
    }
    let to_slot = |id: SigId| SigId(slot[id.0 as usize] as u32);
    let (mut tys, mut defs) = (Vec::with_capacity(count), Vec::with_capacity(count));
    for s in &b.signals {
        if let Global::Real(def, ty) = s {
            tys.push(*ty);
            defs.push(def.map_ids(to_slot));
        }
    }
    let mems = b
        .mems
        .iter()
        .map(|(words, w)| FlatMem { words: words.clone(), write: w.map(|(we, a, d)| (slot[we], slot[a], slot[d])) })
        .collect();
    let comb_order = topological(&defs);
    let names = b.names.into_iter().map(|(name, i)| (name, slot[i])).collect();
    Flat { tys, defs, comb_order, mems, top: slot[..m.signals.len()].to_vec(), names }
}

fn is_comb(d: &Def) -> bool {
    matches!(d, Def::Bin(..) | Def::Un(..) | Def::Mux { .. } | Def::Case { .. } | Def::Concat(_))
}

/// Combinational slots, each after the combinational slots it reads (iterative DFS).
fn topological(defs: &[Def]) -> Vec<usize> {
    const NEW: u8 = 0;
    const OPEN: u8 = 1;
    const DONE: u8 = 2;
    let mut state = vec![NEW; defs.len()];
    let mut order = Vec::new();
    for start in 0..defs.len() {
        if state[start] != NEW || !is_comb(&defs[start]) {
            continue;
        }
        let mut stack = vec![(start, 0usize)];
        state[start] = OPEN;
        while let Some(&mut (node, ref mut next)) = stack.last_mut() {
            let ins = defs[node].comb_inputs();
            if let Some(&dep) = ins.get(*next) {
                *next += 1;
                let dep = dep.0 as usize;
                if !is_comb(&defs[dep]) || state[dep] == DONE {
                    continue;
                }
                assert!(state[dep] != OPEN, "a combinational loop through slot {dep}");
                state[dep] = OPEN;
                stack.push((dep, 0));
            } else {
                state[node] = DONE;
                order.push(node);
                stack.pop();
            }
        }
    }
    order
}
