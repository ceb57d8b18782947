//! The cycle-accurate simulator: a module compiled once to a flat list of operations over
//! u128 slots (one per signal), evaluated in creation order — which is a topological order,
//! because combinational signals only refer to earlier ones. No allocation per cycle.

use super::netlist::{Def, Module, Sig};
use super::width::{BinOp, Ty, UnOp, eval_bin, eval_un};

#[derive(Clone, Debug)]
enum Op {
    Bin { op: BinOp, dst: usize, a: usize, b: usize, ta: Ty, tb: Ty, tr: Ty },
    Un { op: UnOp, dst: usize, a: usize, ta: Ty, tr: Ty },
    Mux { dst: usize, sel: usize, t: usize, f: usize },
    Concat { dst: usize, parts: Vec<(usize, u32)> },
}

#[derive(Clone, Debug)]
struct RegUpdate {
    dst: usize,
    next: usize,
    enable: Option<usize>,
    reset: Option<u128>,
}

#[derive(Clone, Debug)]
struct RomUpdate {
    dst: usize,
    addr: usize,
    rom: usize,
}

#[derive(Clone, Debug)]
pub struct Sim {
    vals: Vec<u128>,
    tys: Vec<Ty>,
    comb: Vec<Op>,
    regs: Vec<RegUpdate>,
    rom_reads: Vec<RomUpdate>,
    roms: Vec<Vec<u128>>,
    /// RAM write ports: (memory, write enable, address, data) slots.
    writes: Vec<(usize, usize, usize, usize)>,
    /// Scratch for the two-phase register update, kept to avoid allocation per cycle.
    next: Vec<u128>,
    /// The `rst` input of the module.
    pub reset: bool,
    pub cycles: u64,
}

impl Sim {
    pub fn new(m: &Module) -> Sim {
        m.check().unwrap_or_else(|e| panic!("{e}"));
        let n = m.signals.len();
        let mut vals = vec![0u128; n];
        let tys: Vec<Ty> = m.signals.iter().map(|s| s.ty).collect();
        let (mut comb, mut regs, mut rom_reads) = (Vec::new(), Vec::new(), Vec::new());
        let ix = |id: super::netlist::SigId| id.0 as usize;
        for (i, s) in m.signals.iter().enumerate() {
            match &s.def {
                Def::Input => {}
                Def::Const(v) => vals[i] = *v,
                Def::Bin(op, a, b) => comb.push(Op::Bin {
                    op: *op,
                    dst: i,
                    a: ix(*a),
                    b: ix(*b),
                    ta: tys[ix(*a)],
                    tb: tys[ix(*b)],
                    tr: s.ty,
                }),
                Def::Un(op, a) => comb.push(Op::Un { op: *op, dst: i, a: ix(*a), ta: tys[ix(*a)], tr: s.ty }),
                Def::Mux { sel, t, f } => comb.push(Op::Mux { dst: i, sel: ix(*sel), t: ix(*t), f: ix(*f) }),
                Def::Concat(parts) => {
                    comb.push(Op::Concat { dst: i, parts: parts.iter().map(|p| (ix(*p), tys[ix(*p)].width)).collect() })
                }
                Def::Reg { next, enable, reset } => {
                    let next = ix(next.expect("checked"));
                    regs.push(RegUpdate { dst: i, next, enable: enable.map(ix), reset: *reset });
                    if let Some(r) = reset {
                        vals[i] = *r;
                    }
                }
                Def::RomRead { rom, addr } => rom_reads.push(RomUpdate { dst: i, addr: ix(*addr), rom: *rom }),
            }
        }
        let roms = m.roms.iter().map(|r| r.words.clone()).collect();
        let writes = m
            .roms
            .iter()
            .enumerate()
            .filter_map(|(k, r)| r.write.map(|(we, a, d)| (k, ix(we), ix(a), ix(d))))
            .collect();
        let next = vec![0; regs.len() + rom_reads.len()];
        let mut sim = Sim { vals, tys, comb, regs, rom_reads, roms, writes, next, reset: false, cycles: 0 };
        sim.eval();
        sim
    }

    pub fn set(&mut self, s: Sig, value: i128) {
        let ty = self.tys[s.id.0 as usize];
        debug_assert!(ty.fits(value) || ty.fits(value - (1i128 << ty.width.min(126))), "value {value} for {ty:?}");
        self.vals[s.id.0 as usize] = ty.wrap(value);
    }

    pub fn get(&self, s: Sig) -> i128 {
        let i = s.id.0 as usize;
        self.tys[i].value(self.vals[i])
    }

    /// Evaluates all combinational logic from the inputs and the current state.
    pub fn eval(&mut self) {
        let v = &mut self.vals;
        for op in &self.comb {
            match *op {
                Op::Bin { op, dst, a, b, ta, tb, tr } => v[dst] = eval_bin(op, ta, v[a], tb, v[b], tr),
                Op::Un { op, dst, a, ta, tr } => v[dst] = eval_un(op, ta, v[a], tr),
                Op::Mux { dst, sel, t, f } => v[dst] = if v[sel] & 1 == 1 { v[t] } else { v[f] },
                Op::Concat { dst, ref parts } => {
                    let mut acc = 0u128;
                    for &(p, w) in parts {
                        acc = if w >= 128 { v[p] } else { (acc << w) | v[p] };
                    }
                    v[dst] = acc;
                }
            }
        }
    }

    /// One rising clock edge: evaluate, latch every register and ROM read, evaluate again so
    /// outputs show the new state.
    pub fn tick(&mut self) {
        self.eval();
        let v = &self.vals;
        for (k, r) in self.regs.iter().enumerate() {
            self.next[k] = match (self.reset, r.reset) {
                (true, Some(init)) => init,
                _ if r.enable.is_none_or(|e| v[e] & 1 == 1) => v[r.next],
                _ => v[r.dst],
            };
        }
        let nr = self.regs.len();
        for (k, r) in self.rom_reads.iter().enumerate() {
            let words = &self.roms[r.rom];
            // Out-of-range addresses read 0, like an unloaded 2-state block RAM word.
            self.next[nr + k] = usize::try_from(v[r.addr]).ok().and_then(|a| words.get(a)).copied().unwrap_or(0);
        }
        // Writes after the reads: a read of the written address sees the old word.
        for &(mem, we, addr, data) in &self.writes {
            if v[we] & 1 == 1 {
                if let Some(w) = usize::try_from(v[addr]).ok().and_then(|a| self.roms[mem].get_mut(a)) {
                    *w = v[data];
                }
            }
        }
        for (k, r) in self.regs.iter().enumerate() {
            self.vals[r.dst] = self.next[k];
        }
        for (k, r) in self.rom_reads.iter().enumerate() {
            self.vals[r.dst] = self.next[nr + k];
        }
        self.cycles += 1;
        self.eval();
    }
}
