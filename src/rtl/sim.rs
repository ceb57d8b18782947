//! The cycle-accurate simulator: a module (with its instances) flattened once to a list of
//! operations over u128 slots, in topological order (`flatten.rs`). No allocation per cycle.

use super::flatten::flatten;
use super::netlist::{Def, Module, Sig, SigId};
use super::sim_ops::{Op, run};
use super::width::Ty;

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
    /// Slot of each top-module signal.
    top: Vec<usize>,
    comb: Vec<Op>,
    regs: Vec<RegUpdate>,
    rom_reads: Vec<RomUpdate>,
    roms: Vec<Vec<u128>>,
    /// RAM write ports: (memory, write enable, address, data) slots.
    writes: Vec<(usize, usize, usize, usize)>,
    /// Scratch for the two-phase register update, kept to avoid allocation per cycle.
    next: Vec<u128>,
    /// Hierarchical signal names (`flatten::Flat::names`), sorted, for `probe`.
    names: Vec<(String, usize)>,
    /// The `rst` input of the module.
    pub reset: bool,
    pub cycles: u64,
    /// An input changed since the last `eval`: `tick` must evaluate before it latches. Saves
    /// one of a cycle's evaluations where the caller evaluates to read outputs before `tick`
    /// (evaluation is idempotent: topological order, no state of its own).
    stale: bool,
}

impl Sim {
    pub fn new(m: &Module) -> Sim {
        let flat = flatten(m);
        let tys = flat.tys;
        let mut vals = vec![0u128; tys.len()];
        let (mut regs, mut rom_reads) = (Vec::new(), Vec::new());
        let ix = |id: SigId| id.0 as usize;
        for (i, def) in flat.defs.iter().enumerate() {
            match def {
                Def::Const(v) => vals[i] = *v,
                Def::Reg { next, enable, reset } => {
                    let next = ix(next.expect("checked"));
                    regs.push(RegUpdate { dst: i, next, enable: enable.map(ix), reset: *reset });
                    if let Some(r) = reset {
                        vals[i] = *r;
                    }
                }
                Def::RomRead { rom, addr } => rom_reads.push(RomUpdate { dst: i, addr: ix(*addr), rom: *rom }),
                _ => {}
            }
        }
        let comb = flat
            .comb_order
            .iter()
            .map(|&i| match &flat.defs[i] {
                Def::Bin(op, a, b) => Op::bin(*op, i, (ix(*a), tys[ix(*a)]), (ix(*b), tys[ix(*b)]), tys[i]),
                Def::Un(op, a) => Op::un(*op, i, (ix(*a), tys[ix(*a)]), tys[i]),
                Def::Mux { sel, t, f } => Op::Mux { dst: i, sel: ix(*sel), t: ix(*t), f: ix(*f) },
                Def::Case { sel, arms, default } => Op::Case {
                    dst: i,
                    sel: ix(*sel),
                    arms: arms.iter().map(|(v, a)| (*v, ix(*a))).collect(),
                    default: ix(*default),
                },
                Def::Concat(parts) => {
                    Op::Concat { dst: i, parts: parts.iter().map(|p| (ix(*p), tys[ix(*p)].width)).collect() }
                }
                other => unreachable!("not combinational: {other:?}"),
            })
            .collect();
        let roms = flat.mems.iter().map(|r| r.words.clone()).collect();
        let writes =
            flat.mems.iter().enumerate().filter_map(|(k, r)| r.write.map(|(we, a, d)| (k, we, a, d))).collect();
        let next = vec![0; regs.len() + rom_reads.len()];
        let mut names = flat.names;
        names.sort();
        let mut sim = Sim {
            vals,
            tys,
            top: flat.top,
            comb,
            regs,
            rom_reads,
            roms,
            writes,
            next,
            names,
            reset: false,
            cycles: 0,
            stale: true,
        };
        sim.eval();
        sim
    }

    pub fn set(&mut self, s: Sig, value: i128) {
        let i = self.top[s.id.0 as usize];
        let ty = self.tys[i];
        debug_assert!(ty.fits(value) || ty.fits(value - (1i128 << ty.width.min(126))), "value {value} for {ty:?}");
        self.vals[i] = ty.wrap(value);
        self.stale = true;
    }

    pub fn get(&self, s: Sig) -> i128 {
        let i = self.top[s.id.0 as usize];
        self.tys[i].value(self.vals[i])
    }

    /// The value of any signal of the hierarchy by its path, `instance/…/signal` (e.g.
    /// `u_traverse_0/g_slot`), as it is now: for debugging and reproducers, not for ports.
    pub fn probe(&self, path: &str) -> Option<i128> {
        let k = self.names.binary_search_by(|(n, _)| n.as_str().cmp(path)).ok()?;
        let i = self.names[k].1;
        Some(self.tys[i].value(self.vals[i]))
    }

    /// Evaluates all combinational logic from the inputs and the current state.
    pub fn eval(&mut self) {
        self.stale = false;
        run(&self.comb, &mut self.vals);
    }

    /// Fills every register, every RAM read register and every written memory with seeded
    /// random bits (ROMs keep their contents): an arbitrary state, as at power-up or in the
    /// middle of any computation. A reset test scrambles, resets for one clock and expects
    /// the design to work from there.
    pub fn scramble(&mut self, seed: u64) {
        let mut rng = crate::rng::SplitMix64(seed);
        let mut random = |ty: Ty| ty.wrap(((rng.next_u64() as u128) << 64 | rng.next_u64() as u128) as i128);
        let dsts: Vec<usize> = self.regs.iter().map(|r| r.dst).chain(self.rom_reads.iter().map(|r| r.dst)).collect();
        for i in dsts {
            self.vals[i] = random(self.tys[i]);
        }
        for &(mem, _, _, data) in &self.writes {
            let ty = self.tys[data];
            for w in self.roms[mem].iter_mut() {
                *w = random(ty);
            }
        }
        self.eval();
    }

    /// One rising clock edge: evaluate (unless nothing changed since the last evaluation),
    /// latch every register and ROM read, evaluate again so outputs show the new state.
    pub fn tick(&mut self) {
        if self.stale {
            self.eval();
        }
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
            if v[we] & 1 == 1
                && let Some(w) = usize::try_from(v[addr]).ok().and_then(|a| self.roms[mem].get_mut(a))
            {
                *w = v[data];
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
