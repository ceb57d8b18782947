//! Time-batched simulation: the same cycle-accurate results as `Sim`, computed a batch of
//! clock cycles ("lanes") at a time.
//!
//! A register that does not feed back on itself is only a delay: its value in cycle c is its
//! input's value in cycle c − 1. So every combinational signal outside a feedback loop is
//! evaluated for B consecutive cycles in one loop, and such a register costs nothing: a reader
//! d registers downstream reads its source d lanes earlier. ROMs are a lookup plus one delay.
//! What does feed back — a state machine, an accumulator, a RAM with its address logic — forms
//! a strongly connected component of the signal graph (registers included). Each such group is
//! evaluated lane by lane, its registers updated from lane c to lane c + 1, while everything
//! around it still runs in whole batches: the design is evaluated group by group in the order
//! of the condensed graph. Each signal keeps the last lanes of the previous batch as history,
//! which starts as the registers' power-up values.
//!
//! Outputs are observed after each clock edge, as `Sim::get` shows them after `tick`: lane
//! c + 1. That is exact for an output with no combinational path from an input; a design with
//! such a path makes `BatchSim::new` return None (use `Sim`, which also serves designs driven
//! interactively, cycle by cycle). The `rst` input is held low.

mod kernels;

use super::flatten::flatten;
use super::netlist::{Def, Module, SigId};
use super::width::Ty;
use kernels::{eval_value, narrow_kernel, wide_kernel};

/// A signal reference: a slot with a buffer, read `delay` cycles late.
#[derive(Clone, Copy, Debug)]
struct Tap {
    base: usize,
    delay: usize,
}

#[derive(Clone, Debug)]
enum Buf {
    Narrow(Vec<i64>),
    Wide(Vec<i128>),
}

/// A combinational definition to evaluate, with its operands.
#[derive(Clone, Debug)]
struct Op {
    def: Def,
    dst: usize,
    srcs: Vec<Tap>,
    src_tys: Vec<Ty>,
}

/// A register updated lane by lane: lane c + 1 from lane c.
#[derive(Clone, Debug)]
struct StateReg {
    dst: usize,
    next: Tap,
    enable: Option<Tap>,
}

/// A feedback group: its combinational operations in evaluation order, its registers, its RAM
/// reads (dst, memory, address) and RAM write ports (memory, enable, address, data).
#[derive(Clone, Debug, Default)]
struct Group {
    ops: Vec<Op>,
    /// ROM lookups (dst, memory, address) in the loop: read one lane later, so computed last.
    lookups: Vec<(usize, usize, Tap)>,
    regs: Vec<StateReg>,
    reads: Vec<(usize, usize, Tap)>,
    writes: Vec<(usize, Tap, Tap, Tap)>,
}

#[derive(Clone, Debug)]
enum Step {
    /// A combinational operation over every lane of the batch.
    Lanes(Op),
    /// A ROM lookup over every lane: dst = rom[addr].
    Lookup {
        dst: usize,
        mem: usize,
        addr: Tap,
    },
    Group(Group),
}

#[derive(Clone, Debug)]
pub struct BatchSim {
    batch: usize,
    tys: Vec<Ty>,
    /// History lanes kept in front of each slot's current batch.
    hist: Vec<usize>,
    bufs: Vec<Buf>,
    steps: Vec<Step>,
    inputs: Vec<usize>,
    outputs: Vec<Tap>,
    mems: Vec<Vec<u128>>,
    scratch: Vec<Vec<i128>>,
    /// The first lane of the next batch (lanes computed so far).
    lane0: usize,
}

/// How a slot of the flat design is simulated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Source,
    Comb,
    /// A register without enable or reset (a delay unless it is in a feedback group).
    Delay,
    State,
    /// A read of a ROM (no write port): a lookup slot, then one delay.
    RomRead,
    RamRead,
}

impl BatchSim {
    pub fn new(m: &Module, batch: usize) -> Option<BatchSim> {
        let flat = flatten(m);
        let n = flat.defs.len();
        let ix = |id: SigId| id.0 as usize;
        let mut kind: Vec<Kind> = flat
            .defs
            .iter()
            .map(|d| match d {
                Def::Input | Def::Const(_) => Kind::Source,
                Def::Reg { enable: None, reset: None, .. } => Kind::Delay,
                Def::Reg { .. } => Kind::State,
                Def::RomRead { rom, .. } if flat.mems[*rom].write.is_none() => Kind::RomRead,
                Def::RomRead { .. } => Kind::RamRead,
                _ => Kind::Comb,
            })
            .collect();
        // Graph nodes: slots, then a lookup per ROM read, then one per RAM.
        let lookups: Vec<usize> = (0..n).filter(|&s| kind[s] == Kind::RomRead).collect();
        let lookup_of = |s: usize| n + lookups.iter().position(|&x| x == s).expect("a ROM read");
        let rams: Vec<usize> = (0..flat.mems.len()).filter(|&k| flat.mems[k].write.is_some()).collect();
        let ram_node = |mem: usize| n + lookups.len() + rams.iter().position(|&x| x == mem).expect("a RAM");
        let nodes = n + lookups.len() + rams.len();
        let mut deps: Vec<Vec<usize>> = vec![Vec::new(); nodes];
        for s in 0..n {
            deps[s] = match &flat.defs[s] {
                Def::Reg { next, enable, .. } => next.iter().chain(enable.iter()).map(|x| ix(*x)).collect(),
                Def::RomRead { addr, rom } if kind[s] == Kind::RomRead => {
                    deps[lookup_of(s)] = vec![ix(*addr)];
                    let _ = rom;
                    vec![lookup_of(s)]
                }
                Def::RomRead { addr, rom } => {
                    deps[ram_node(*rom)].push(s);
                    vec![ix(*addr), ram_node(*rom)]
                }
                d => d.comb_inputs().into_iter().map(ix).collect(),
            };
        }
        for &k in &rams {
            let (we, a, d) = flat.mems[k].write.expect("a RAM");
            deps[ram_node(k)].extend([we, a, d]);
        }
        let sccs = tarjan(&deps);
        // Registers in a feedback group are state; the others stay delays.
        for scc in &sccs {
            let cyclic = scc.len() > 1 || deps[scc[0]].contains(&scc[0]);
            for &s in scc.iter().filter(|&&s| s < n) {
                if cyclic && kind[s] == Kind::Delay {
                    kind[s] = Kind::State;
                }
            }
        }
        // Every slot as a tap into a buffer: delays chain to their source.
        let mut taps: Vec<Option<Tap>> = vec![None; n];
        fn resolve(
            s: usize,
            kind: &[Kind],
            defs: &[Def],
            lookup: &dyn Fn(usize) -> usize,
            taps: &mut [Option<Tap>],
        ) -> Tap {
            if let Some(t) = taps[s] {
                return t;
            }
            let t = match (kind[s], &defs[s]) {
                (Kind::Delay, Def::Reg { next: Some(x), .. }) => {
                    let t = resolve(x.0 as usize, kind, defs, lookup, taps);
                    Tap { base: t.base, delay: t.delay + 1 }
                }
                (Kind::RomRead, _) => Tap { base: lookup(s), delay: 1 },
                _ => Tap { base: s, delay: 0 },
            };
            taps[s] = Some(t);
            t
        }
        for s in 0..n {
            resolve(s, &kind, &flat.defs, &lookup_of, &mut taps);
        }
        let taps: Vec<Tap> = taps.into_iter().map(|t| t.expect("resolved")).collect();
        let tap = |id: SigId| taps[ix(id)];
        let mut tys = flat.tys.clone();
        tys.extend(lookups.iter().map(|&s| flat.tys[s]));
        let slots = n + lookups.len();
        let mut hist = vec![0usize; slots];
        let mut note = |t: Tap, hist: &mut Vec<usize>| hist[t.base] = hist[t.base].max(t.delay);
        let op_of = |s: usize, hist: &mut Vec<usize>, note: &mut dyn FnMut(Tap, &mut Vec<usize>)| {
            let srcs: Vec<Tap> = flat.defs[s].comb_inputs().into_iter().map(tap).collect();
            srcs.iter().for_each(|t| note(*t, hist));
            let src_tys = srcs
                .iter()
                .map(|t| if t.base < n { flat.tys[t.base] } else { flat.tys[lookups[t.base - n]] })
                .collect();
            Op { def: flat.defs[s].clone(), dst: s, srcs, src_tys }
        };
        let mut steps = Vec::new();
        for scc in &sccs {
            let cyclic = scc.len() > 1 || deps[scc[0]].contains(&scc[0]);
            let stateful = scc.iter().any(|&s| s >= slots || (s < n && matches!(kind[s], Kind::State | Kind::RamRead)));
            if !cyclic && !stateful {
                let s = scc[0];
                if s >= n {
                    let reader = lookups[s - n];
                    let Def::RomRead { rom, addr } = flat.defs[reader] else { unreachable!("a ROM read") };
                    note(tap(addr), &mut hist);
                    steps.push(Step::Lookup { dst: s, mem: rom, addr: tap(addr) });
                } else if kind[s] == Kind::Comb {
                    steps.push(Step::Lanes(op_of(s, &mut hist, &mut note)));
                }
                continue;
            }
            let mut g = Group::default();
            // Combinational members in an order where same-lane operands come first.
            let members: Vec<usize> = scc.iter().copied().filter(|&s| s < n && kind[s] == Kind::Comb).collect();
            for s in same_lane_order(&members, &flat.defs, &taps) {
                g.ops.push(op_of(s, &mut hist, &mut note));
            }
            for &s in scc.iter().filter(|&&s| s < n) {
                match (&flat.defs[s], kind[s]) {
                    (Def::Reg { next, enable, .. }, Kind::State) => {
                        let next = tap(next.expect("checked"));
                        let enable = enable.map(tap);
                        note(next, &mut hist);
                        enable.iter().for_each(|t| note(*t, &mut hist));
                        g.regs.push(StateReg { dst: s, next, enable });
                    }
                    (Def::RomRead { rom, addr }, Kind::RamRead) => {
                        note(tap(*addr), &mut hist);
                        g.reads.push((s, *rom, tap(*addr)));
                    }
                    _ => {}
                }
            }
            for &s in scc.iter().filter(|&&s| s >= n && s < slots) {
                let Def::RomRead { rom, addr } = flat.defs[lookups[s - n]] else { unreachable!("a ROM read") };
                note(tap(addr), &mut hist);
                g.lookups.push((s, rom, tap(addr)));
            }
            for &node in scc.iter().filter(|&&s| s >= slots) {
                let mem = rams[node - slots];
                let (we, a, d) = flat.mems[mem].write.expect("a RAM");
                let (we, a, d) = (taps[we], taps[a], taps[d]);
                [we, a, d].iter().for_each(|t| note(*t, &mut hist));
                g.writes.push((mem, we, a, d));
            }
            steps.push(Step::Group(g));
        }
        // Outputs: lane c + 1, which must not depend on that lane's inputs.
        let top = |id: SigId| flat.top[ix(id)];
        let outputs: Vec<Tap> = m.outputs.iter().map(|(_, id)| taps[top(*id)]).collect();
        let inputs: Vec<usize> = m.inputs.iter().map(|&i| top(i)).collect();
        if outputs.iter().any(|t| reaches_input(t.base, t.delay, &flat.defs, &taps, &kind)) {
            return None;
        }
        outputs.iter().for_each(|t| note(*t, &mut hist));
        let init = |s: usize| -> (i128, i128) {
            if s >= n {
                return (0, 0);
            }
            match flat.defs[s] {
                // A constant's history is 0: it stands for a register loading it before the first edge.
                Def::Const(bits) => (0, flat.tys[s].value(bits)),
                // History is what a delay register reading this one held before: its power-up 0.
                Def::Reg { reset: Some(r), .. } => (0, flat.tys[s].value(r)),
                _ => (0, 0),
            }
        };
        let bufs = (0..slots)
            .map(|s| {
                let (h, ty) = (hist[s], tys[s]);
                let (before, from) = init(s);
                // State starts at lane 0 (index h) with its power-up value.
                let lane = |k: usize| if k < h { before } else { from };
                let len = h + batch + 1;
                if ty.width < 64 || ty == Ty::s(64) {
                    Buf::Narrow((0..len).map(|k| lane(k) as i64).collect())
                } else {
                    Buf::Wide((0..len).map(lane).collect())
                }
            })
            .collect();
        let mems = flat.mems.iter().map(|x| x.words.clone()).collect();
        Some(BatchSim { batch, tys, hist, bufs, steps, inputs, outputs, mems, scratch: Vec::new(), lane0: 0 })
    }

    /// Runs `cycles` clock cycles from power-up. `input(c, k)` is input k's value in cycle c;
    /// `output(c, k, v)` receives output k's value after cycle c's clock edge (what `Sim::get`
    /// shows after `tick`).
    pub fn run(&mut self, cycles: usize, input: impl Fn(usize, usize) -> i128, output: impl FnMut(usize, usize, i128)) {
        // One lane more than cycles: the outputs of cycle c are lane c + 1.
        self.advance(cycles + 1, |c, k| if c < cycles { input(c, k) } else { 0 }, output);
    }

    /// Computes the next `lanes` lanes (lane c holds cycle c before its edge), continuing where
    /// the last call stopped, and reports every output of cycle c − 1 from lane c ≥ 1.
    pub fn advance(
        &mut self,
        lanes: usize,
        input: impl Fn(usize, usize) -> i128,
        mut output: impl FnMut(usize, usize, i128),
    ) {
        let end = self.lane0 + lanes;
        while self.lane0 < end {
            let done = self.lane0;
            let lanes = self.batch.min(end - done);
            for (k, &slot) in self.inputs.iter().enumerate() {
                let (h, ty) = (self.hist[slot], self.tys[slot]);
                for c in 0..lanes {
                    let v = ty.value(ty.wrap(input(done + c, k)));
                    match &mut self.bufs[slot] {
                        Buf::Narrow(b) => b[h + c] = v as i64,
                        Buf::Wide(b) => b[h + c] = v,
                    }
                }
            }
            for i in 0..self.steps.len() {
                self.step(i, lanes);
            }
            for c in 0..lanes {
                if done + c >= 1 {
                    for (k, t) in self.outputs.iter().enumerate() {
                        output(done + c - 1, k, self.lane(*t, c));
                    }
                }
            }
            // Keep the last lanes, and the state for the next lane, as the next batch's history.
            for (slot, b) in self.bufs.iter_mut().enumerate() {
                let h = self.hist[slot];
                match b {
                    Buf::Narrow(v) => v.copy_within(lanes..=lanes + h, 0),
                    Buf::Wide(v) => v.copy_within(lanes..=lanes + h, 0),
                }
            }
            self.lane0 += lanes;
        }
    }

    #[inline]
    fn lane(&self, t: Tap, c: usize) -> i128 {
        let i = self.hist[t.base] + c - t.delay;
        match &self.bufs[t.base] {
            Buf::Narrow(b) => b[i] as i128,
            Buf::Wide(b) => b[i],
        }
    }

    #[inline]
    fn set(&mut self, slot: usize, c: usize, v: i128) {
        let i = self.hist[slot] + c;
        match &mut self.bufs[slot] {
            Buf::Narrow(b) => b[i] = v as i64,
            Buf::Wide(b) => b[i] = v,
        }
    }

    /// The word of memory `mem` at the address `addr` holds in lane c, as a value of slot
    /// `dst`'s type; out-of-range addresses read 0, as in `Sim`.
    fn read_mem(&self, mem: usize, addr: Tap, c: usize, dst: usize) -> i128 {
        let a = self.lane(addr, c);
        let bits = usize::try_from(a).ok().and_then(|a| self.mems[mem].get(a)).copied().unwrap_or(0);
        self.tys[dst].value(bits)
    }

    fn step(&mut self, i: usize, lanes: usize) {
        let step = std::mem::replace(&mut self.steps[i], Step::Group(Group::default()));
        match &step {
            Step::Lanes(op) => self.eval_lanes(op, lanes),
            Step::Lookup { dst, mem, addr } => {
                for c in 0..lanes {
                    let v = self.read_mem(*mem, *addr, c, *dst);
                    self.set(*dst, c, v);
                }
            }
            Step::Group(g) => {
                for c in 0..lanes {
                    self.group_lane(g, c);
                }
            }
        }
        self.steps[i] = step;
    }

    /// One lane of a feedback group: its combinational values in lane c, then its state in
    /// lane c + 1 (RAM reads before RAM writes: read-first, as block RAM).
    fn group_lane(&mut self, g: &Group, c: usize) {
        // Operands on the stack: a case or concatenation may have many.
        let mut vals = [0i128; 16];
        for op in &g.ops {
            let v = if op.srcs.len() <= vals.len() {
                for (k, t) in op.srcs.iter().enumerate() {
                    vals[k] = self.lane(*t, c);
                }
                eval_value(&op.def, &op.src_tys, &vals[..op.srcs.len()], self.tys[op.dst])
            } else {
                let many: Vec<i128> = op.srcs.iter().map(|t| self.lane(*t, c)).collect();
                eval_value(&op.def, &op.src_tys, &many, self.tys[op.dst])
            };
            self.set(op.dst, c, v);
        }
        for &(dst, mem, addr) in &g.lookups {
            let v = self.read_mem(mem, addr, c, dst);
            self.set(dst, c, v);
        }
        for r in &g.regs {
            let load = r.enable.is_none_or(|e| self.lane(e, c) != 0);
            let v = if load { self.lane(r.next, c) } else { self.lane(Tap { base: r.dst, delay: 0 }, c) };
            self.set(r.dst, c + 1, v);
        }
        for &(dst, mem, addr) in &g.reads {
            let v = self.read_mem(mem, addr, c, dst);
            self.set(dst, c + 1, v);
        }
        for &(mem, we, addr, data) in &g.writes {
            if self.lane(we, c) != 0 {
                let a = self.lane(addr, c);
                let bits = self.tys[data.base].wrap(self.lane(data, c));
                if let Some(w) = usize::try_from(a).ok().and_then(|a| self.mems[mem].get_mut(a)) {
                    *w = bits;
                }
            }
        }
    }

    /// A combinational operation over all lanes: i64 loops when everything is narrow, else
    /// i128 loops, else value by value through the shared width rules.
    fn eval_lanes(&mut self, op: &Op, lanes: usize) {
        let mut out = std::mem::replace(&mut self.bufs[op.dst], Buf::Narrow(Vec::new()));
        let h = self.hist[op.dst];
        let narrow: Option<Vec<&[i64]>> = op
            .srcs
            .iter()
            .map(|t| match &self.bufs[t.base] {
                Buf::Narrow(b) => {
                    let start = self.hist[t.base] - t.delay;
                    Some(&b[start..start + lanes])
                }
                Buf::Wide(_) => None,
            })
            .collect();
        let done = match (&mut out, narrow) {
            (Buf::Narrow(o), Some(srcs)) => {
                narrow_kernel(&op.def, &op.src_tys, self.tys[op.dst], &srcs, &mut o[h..h + lanes])
            }
            _ => false,
        };
        if !done {
            self.eval_wide(op, lanes, &mut out);
        }
        self.bufs[op.dst] = out;
    }

    fn eval_wide(&mut self, op: &Op, lanes: usize, out: &mut Buf) {
        let tr = self.tys[op.dst];
        let src_tys: Vec<Ty> = op.srcs.iter().map(|t| self.tys[t.base]).collect();
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.resize(op.srcs.len() + 1, Vec::new());
        for (k, t) in op.srcs.iter().enumerate() {
            let start = self.hist[t.base] - t.delay;
            let s = &mut scratch[k];
            s.clear();
            match &self.bufs[t.base] {
                Buf::Narrow(b) => s.extend(b[start..start + lanes].iter().map(|&x| x as i128)),
                Buf::Wide(b) => s.extend_from_slice(&b[start..start + lanes]),
            }
        }
        let (ins, res) = scratch.split_at_mut(op.srcs.len());
        let r = &mut res[0];
        r.clear();
        r.resize(lanes, 0);
        if !wide_kernel(&op.def, &src_tys, tr, ins, r) {
            // One operand buffer for all lanes: no allocation per lane.
            let mut bits = vec![0u128; src_tys.len()];
            for c in 0..lanes {
                for (k, ty) in src_tys.iter().enumerate() {
                    bits[k] = ty.wrap(ins[k][c]);
                }
                r[c] = tr.value(op.def.eval(&src_tys, &bits, tr));
            }
        }
        let h = self.hist[op.dst];
        match out {
            Buf::Narrow(o) => o[h..h + lanes].iter_mut().zip(r.iter()).for_each(|(o, &x)| *o = x as i64),
            Buf::Wide(o) => o[h..h + lanes].copy_from_slice(r),
        }
        self.scratch = scratch;
    }
}

/// Whether the slot read at `delay` depends on a top-level input in the same cycle.
fn reaches_input(base: usize, delay: usize, defs: &[Def], taps: &[Tap], kind: &[Kind]) -> bool {
    if delay > 0 || base >= defs.len() {
        return false;
    }
    let mut seen = vec![false; defs.len()];
    let mut stack = vec![base];
    while let Some(s) = stack.pop() {
        if std::mem::replace(&mut seen[s], true) {
            continue;
        }
        match (&defs[s], kind[s]) {
            (Def::Input, _) => return true,
            (d, Kind::Comb) => stack.extend(
                d.comb_inputs()
                    .into_iter()
                    .map(|x| taps[x.0 as usize])
                    .filter(|t| t.delay == 0 && t.base < defs.len())
                    .map(|t| t.base),
            ),
            _ => {}
        }
    }
    false
}

/// Group members ordered so that each comes after the members it reads in the same lane.
fn same_lane_order(members: &[usize], defs: &[Def], taps: &[Tap]) -> Vec<usize> {
    let mut order = Vec::with_capacity(members.len());
    let mut state = std::collections::HashMap::new();
    for &start in members {
        if state.contains_key(&start) {
            continue;
        }
        state.insert(start, 1u8);
        let mut stack = vec![(start, 0usize)];
        while let Some(&mut (s, ref mut next)) = stack.last_mut() {
            let ins = defs[s].comb_inputs();
            if let Some(&x) = ins.get(*next) {
                *next += 1;
                let t = taps[x.0 as usize];
                if t.delay == 0 && members.contains(&t.base) && !state.contains_key(&t.base) {
                    state.insert(t.base, 1);
                    stack.push((t.base, 0));
                }
            } else {
                state.insert(s, 2);
                order.push(s);
                stack.pop();
            }
        }
    }
    order
}

/// Strongly connected components of the graph where node v depends on `deps[v]`, each after
/// the components it depends on (Tarjan's algorithm, iterative).
fn tarjan(deps: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = deps.len();
    let (mut index, mut low, mut on) = (vec![usize::MAX; n], vec![0usize; n], vec![false; n]);
    let (mut next_index, mut stack, mut out) = (0usize, Vec::new(), Vec::new());
    for root in 0..n {
        if index[root] != usize::MAX {
            continue;
        }
        let mut call = vec![(root, 0usize)];
        index[root] = next_index;
        low[root] = next_index;
        next_index += 1;
        stack.push(root);
        on[root] = true;
        while let Some(&mut (v, ref mut k)) = call.last_mut() {
            if let Some(&w) = deps[v].get(*k) {
                *k += 1;
                if index[w] == usize::MAX {
                    index[w] = next_index;
                    low[w] = next_index;
                    next_index += 1;
                    stack.push(w);
                    on[w] = true;
                    call.push((w, 0));
                } else if on[w] {
                    low[v] = low[v].min(index[w]);
                }
            } else {
                call.pop();
                if let Some(&(parent, _)) = call.last() {
                    low[parent] = low[parent].min(low[v]);
                }
                if low[v] == index[v] {
                    let mut scc = Vec::new();
                    while let Some(w) = stack.pop() {
                        on[w] = false;
                        scc.push(w);
                        if w == v {
                            break;
                        }
                    }
                    scc.sort_unstable();
                    out.push(scc);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests;
