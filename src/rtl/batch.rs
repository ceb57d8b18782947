//! Time-batched simulation of feed-forward designs (pipelines): the same cycle-accurate
//! results as `Sim`, computed a batch of clock cycles at a time.
//!
//! In a design where no register feeds back on itself, a register is only a delay: its value
//! in cycle c is its input's value in cycle c − 1. So every combinational signal can be
//! evaluated for B consecutive cycles in one loop (one "lane" per cycle), and a register is
//! not evaluated at all: a reader of a register d stages deep reads its source signal d lanes
//! earlier. Each signal keeps the last few lanes of the previous batch as history. This turns
//! ~1,100 interpreted operations per cycle into ~580 vectorisable loops per batch.
//!
//! Values are held as sign- or zero-extended integers (i64 lanes up to 64 bits, i128 beyond).
//! The common all-64-bit operations have their own loops; anything touching a wider signal
//! goes through `width::eval_bin`/`eval_un`, the rules the printers and `Sim` use.
//!
//! Supported: inputs, constants, all combinational definitions, registers without enable or
//! reset, outputs driven by registers. Anything else (feedback, enables, memories, outputs
//! with a combinational path from an input) makes `BatchSim::new` return None; use `Sim`.

use super::flatten::flatten;
use super::netlist::{Def, Module, SigId};
use super::width::{BinOp, Ty, UnOp, eval_bin, eval_un};

/// A signal reference: the slot of a combinational signal or input, read `delay` cycles late.
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

#[derive(Clone, Debug)]
struct Op {
    def: Def,
    dst: usize,
    srcs: Vec<Tap>,
}

#[derive(Clone, Debug)]
pub struct BatchSim {
    batch: usize,
    tys: Vec<Ty>,
    /// History lanes kept in front of each slot's current batch.
    hist: Vec<usize>,
    bufs: Vec<Buf>,
    ops: Vec<Op>,
    inputs: Vec<usize>,
    /// Each output's source, read at `delay − 1` (outputs are registers, observed after the edge).
    outputs: Vec<Tap>,
    /// Reused lane buffers of the wide path.
    scratch: Vec<Vec<i128>>,
}

impl BatchSim {
    pub fn new(m: &Module, batch: usize) -> Option<BatchSim> {
        let flat = flatten(m);
        if !flat.mems.is_empty() {
            return None;
        }
        let n = flat.defs.len();
        // Resolve every slot to (base, delay); registers chain to their inputs.
        let mut taps: Vec<Option<Tap>> = vec![None; n];
        for start in 0..n {
            let mut chain = Vec::new();
            let mut s = start;
            let tap = loop {
                if let Some(t) = taps[s] {
                    break t;
                }
                match &flat.defs[s] {
                    Def::Reg { next, enable: None, reset: None } => {
                        if chain.len() > n {
                            return None; // registers in a loop
                        }
                        chain.push(s);
                        s = next.expect("checked").0 as usize;
                    }
                    Def::Reg { .. } | Def::RomRead { .. } => return None,
                    _ => break Tap { base: s, delay: 0 },
                }
            };
            for (k, &r) in chain.iter().rev().enumerate() {
                taps[r] = Some(Tap { base: tap.base, delay: tap.delay + k + 1 });
            }
            taps[s] = Some(tap);
        }
        let taps: Vec<Tap> = taps.into_iter().map(|t| t.expect("resolved")).collect();
        let tap = |id: SigId| taps[id.0 as usize];
        // Combinational operations in dependency order (through registers too: a reader of a
        // delayed lane still needs this batch's lanes of its base). A cycle is feedback.
        let order = ordered(&flat.defs, &taps)?;
        let mut hist = vec![0usize; n];
        let mut ops = Vec::with_capacity(order.len());
        for &i in &order {
            let srcs: Vec<Tap> = flat.defs[i].comb_inputs().into_iter().map(tap).collect();
            for t in &srcs {
                hist[t.base] = hist[t.base].max(t.delay);
            }
            ops.push(Op { def: flat.defs[i].clone(), dst: i, srcs });
        }
        let top = |id: SigId| flat.top[id.0 as usize];
        let mut outputs = Vec::new();
        for (_, id) in &m.outputs {
            let t = taps[top(*id)];
            if t.delay == 0 {
                return None; // a combinational output: observed after the edge, not batchable
            }
            hist[t.base] = hist[t.base].max(t.delay - 1);
            outputs.push(Tap { base: t.base, delay: t.delay - 1 });
        }
        let inputs: Vec<usize> = m.inputs.iter().map(|&i| top(i)).collect();
        // History starts at 0: it stands for the registers' power-up value, even behind a
        // constant (a register loading a constant reads 0 until its first clock edge).
        let bufs = (0..n)
            .map(|i| {
                let (h, ty) = (hist[i], flat.tys[i]);
                let value = match flat.defs[i] {
                    Def::Const(bits) => ty.value(bits),
                    _ => 0,
                };
                let lane = |k: usize| if k < h { 0 } else { value };
                // u64 values do not fit an i64 lane as extended integers.
                if ty.width < 64 || ty == Ty::s(64) {
                    Buf::Narrow((0..h + batch).map(|k| lane(k) as i64).collect())
                } else {
                    Buf::Wide((0..h + batch).map(lane).collect())
                }
            })
            .collect();
        Some(BatchSim { batch, tys: flat.tys, hist, bufs, ops, inputs, outputs, scratch: Vec::new() })
    }

    /// Runs `cycles` clock cycles. `input(c, k)` is input k's value in cycle c; `output(c, k, v)`
    /// receives output k's value after cycle c's clock edge (what `Sim::get` shows after `tick`).
    pub fn run(&mut self, cycles: usize, input: impl Fn(usize, usize) -> i128, mut output: impl FnMut(usize, usize, i128)) {
        let mut done = 0;
        while done < cycles {
            let lanes = self.batch.min(cycles - done);
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
            for i in 0..self.ops.len() {
                self.eval(i, lanes);
            }
            for c in 0..lanes {
                for (k, t) in self.outputs.iter().enumerate() {
                    output(done + c, k, self.lane(*t, c));
                }
            }
            // Keep the last lanes as the next batch's history.
            for (slot, b) in self.bufs.iter_mut().enumerate() {
                let h = self.hist[slot];
                match b {
                    Buf::Narrow(v) => v.copy_within(lanes..lanes + h, 0),
                    Buf::Wide(v) => v.copy_within(lanes..lanes + h, 0),
                }
            }
            done += lanes;
        }
    }

    fn lane(&self, t: Tap, c: usize) -> i128 {
        let i = self.hist[t.base] + c - t.delay;
        match &self.bufs[t.base] {
            Buf::Narrow(b) => b[i] as i128,
            Buf::Wide(b) => b[i],
        }
    }

    fn eval(&mut self, i: usize, lanes: usize) {
        let dst = self.ops[i].dst;
        let mut out = std::mem::replace(&mut self.bufs[dst], Buf::Narrow(Vec::new()));
        if !self.eval_narrow(i, lanes, &mut out) {
            self.eval_wide(i, lanes, &mut out);
        }
        self.bufs[dst] = out;
    }

    /// The all-narrow case through `narrow_kernel`; false if it does not apply.
    fn eval_narrow(&self, i: usize, lanes: usize, out: &mut Buf) -> bool {
        let op = &self.ops[i];
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
        match (out, narrow) {
            (Buf::Narrow(o), Some(srcs)) => narrow_kernel(&op.def, &self.tys, op, &srcs, &mut o[h..h + lanes]),
            _ => false,
        }
    }
}

impl BatchSim {
    /// Operations touching a signal wider than 64 bits: operands gathered as i128 lanes,
    /// common operators in i128 loops, the rest per lane through the shared width rules.
    fn eval_wide(&mut self, i: usize, lanes: usize, out: &mut Buf) {
        let op = &self.ops[i];
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
            let mut bits = [0u128; 3];
            for c in 0..lanes {
                let mut many = Vec::new();
                let b: &[u128] = if ins.len() <= 3 {
                    for (k, ty) in src_tys.iter().enumerate() {
                        bits[k] = ty.wrap(ins[k][c]);
                    }
                    &bits[..ins.len()]
                } else {
                    many.extend(src_tys.iter().enumerate().map(|(k, ty)| ty.wrap(ins[k][c])));
                    &many
                };
                r[c] = tr.value(eval_bits(&op.def, &src_tys, b, tr));
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

/// `x` wrapped to a type of 128 − `sh` bits as an extended integer.
#[inline(always)]
fn fit128(x: i128, sh: u32, signed: bool) -> i128 {
    if signed { (x << sh) >> sh } else { ((x as u128) << sh >> sh) as i128 }
}

/// i128 loops for the wide operators the cores use. Unsigned 128-bit values do not fit an
/// i128 as extended integers, so anything involving one is left to the general path.
fn wide_kernel(def: &Def, tys: &[Ty], tr: Ty, s: &[Vec<i128>], o: &mut [i128]) -> bool {
    if tys.iter().chain([&tr]).any(|t| t.width == 128 && !t.signed) {
        return false;
    }
    let (sh, sg) = (128 - tr.width, tr.signed);
    match def {
        Def::Bin(op, ..) => {
            let (a, b) = (&s[0], &s[1]);
            let f: fn(i128, i128) -> i128 = match op {
                BinOp::Add => |a, b| a.wrapping_add(b),
                BinOp::Sub => |a, b| a.wrapping_sub(b),
                BinOp::Mul => |a, b| a.wrapping_mul(b),
                BinOp::And => |a, b| a & b,
                BinOp::Or => |a, b| a | b,
                BinOp::Xor => |a, b| a ^ b,
                BinOp::Eq => |a, b| (a == b) as i128,
                BinOp::Ne => |a, b| (a != b) as i128,
                BinOp::Lt => |a, b| (a < b) as i128,
                BinOp::Le => |a, b| (a <= b) as i128,
            };
            for ((o, &x), &y) in o.iter_mut().zip(a).zip(b) {
                *o = fit128(f(x, y), sh, sg);
            }
        }
        Def::Un(op, _) => {
            let a = &s[0];
            match *op {
                UnOp::Shr(k) => o.iter_mut().zip(a).for_each(|(o, &x)| *o = x >> k),
                UnOp::Shl(k) => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x << k, sh, sg)),
                UnOp::Slice { lsb, .. } => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x >> lsb, sh, false)),
                UnOp::Resize(_) | UnOp::AsSigned | UnOp::AsUnsigned => {
                    o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x, sh, sg))
                }
                UnOp::Not => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(!x, sh, sg)),
                UnOp::Neg => o.iter_mut().zip(a).for_each(|(o, &x)| *o = fit128(x.wrapping_neg(), sh, sg)),
            }
        }
        Def::Mux { .. } => {
            for (((o, &c), &x), &y) in o.iter_mut().zip(&s[0]).zip(&s[1]).zip(&s[2]) {
                *o = if c != 0 { x } else { y };
            }
        }
        _ => return false,
    }
    true
}

/// One definition on bit patterns (operands in `comb_inputs` order), by the shared rules.
fn eval_bits(def: &Def, tys: &[Ty], b: &[u128], tr: Ty) -> u128 {
    match def {
        Def::Bin(op, ..) => eval_bin(*op, tys[0], b[0], tys[1], b[1], tr),
        Def::Un(op, _) => eval_un(*op, tys[0], b[0], tr),
        Def::Mux { .. } => {
            if b[0] & 1 == 1 {
                b[1]
            } else {
                b[2]
            }
        }
        // comb_inputs order: sel, default, arms…
        Def::Case { arms, .. } => arms.iter().position(|a| a.0 == b[0]).map_or(b[1], |k| b[2 + k]),
        Def::Concat(_) => tys.iter().zip(b).fold(0u128, |acc, (t, v)| if t.width >= 128 { *v } else { (acc << t.width) | v }),
        other => unreachable!("not combinational: {other:?}"),
    }
}

/// `x` wrapped to `t` as an extended integer (t.width ≤ 64).
#[inline(always)]
fn fit(x: i64, sh: u32, signed: bool) -> i64 {
    if signed { (x << sh) >> sh } else { ((x as u64) << sh >> sh) as i64 }
}

/// The all-narrow loops. Returns false for what it does not cover (the caller falls back).
fn narrow_kernel(def: &Def, tys: &[Ty], op: &Op, s: &[&[i64]], o: &mut [i64]) -> bool {
    let tr = tys[op.dst];
    let (sh, sg) = (64 - tr.width, tr.signed);
    let ta = op.srcs.first().map(|t| tys[t.base]);
    macro_rules! lanes {
        (|$a:ident| $e:expr) => {{
            let a = s[0];
            for (o, &$a) in o.iter_mut().zip(a) {
                *o = $e;
            }
        }};
        (|$a:ident, $b:ident| $e:expr) => {{
            let (a, b) = (s[0], s[1]);
            for ((o, &$a), &$b) in o.iter_mut().zip(a).zip(b) {
                *o = $e;
            }
        }};
    }
    match def {
        Def::Bin(op, ..) => match op {
            BinOp::Add => lanes!(|a, b| fit(a.wrapping_add(b), sh, sg)),
            BinOp::Sub => lanes!(|a, b| fit(a.wrapping_sub(b), sh, sg)),
            BinOp::And => lanes!(|a, b| a & b),
            BinOp::Or => lanes!(|a, b| a | b),
            BinOp::Xor => lanes!(|a, b| a ^ b),
            // wa + wb ≤ 64: the product of the values is exact.
            BinOp::Mul => lanes!(|a, b| a.wrapping_mul(b)),
            BinOp::Eq => lanes!(|a, b| (a == b) as i64),
            BinOp::Ne => lanes!(|a, b| (a != b) as i64),
            BinOp::Lt => lanes!(|a, b| (a < b) as i64),
            BinOp::Le => lanes!(|a, b| (a <= b) as i64),
        },
        Def::Un(op, _) => {
            let ta = ta.expect("one operand");
            match *op {
                UnOp::Not => lanes!(|a| fit(!a, sh, sg)),
                UnOp::Neg => lanes!(|a| fit(a.wrapping_neg(), sh, sg)),
                UnOp::Shl(k) => lanes!(|a| fit(a << k, sh, sg)),
                // Extended values: >> is arithmetic for signed, logical for unsigned (a ≥ 0).
                UnOp::Shr(k) => lanes!(|a| a >> k),
                UnOp::Slice { lsb, .. } => lanes!(|a| fit(a >> lsb, sh, false)),
                UnOp::Resize(_) | UnOp::AsSigned | UnOp::AsUnsigned => {
                    // Reinterpret the operand's bit pattern in the result type.
                    let _ = ta;
                    lanes!(|a| fit(a, sh, sg))
                }
            }
        }
        Def::Mux { .. } => {
            let (sel, t, f) = (s[0], s[1], s[2]);
            for (((o, &c), &x), &y) in o.iter_mut().zip(sel).zip(t).zip(f) {
                *o = if c != 0 { x } else { y };
            }
        }
        _ => return false,
    }
    true
}

/// Slots with combinational definitions, each after the bases of its operands; None if the
/// graph (registers included, as delays) has a cycle.
fn ordered(defs: &[Def], taps: &[Tap]) -> Option<Vec<usize>> {
    let is_comb = |i: usize| taps[i].delay == 0 && !matches!(defs[i], Def::Input | Def::Const(_));
    let mut state = vec![0u8; defs.len()];
    let mut order = Vec::new();
    for start in (0..defs.len()).filter(|&i| is_comb(i)) {
        if state[start] != 0 {
            continue;
        }
        state[start] = 1;
        let mut stack = vec![(start, defs[start].comb_inputs(), 0usize)];
        while let Some((node, ins, next)) = stack.last_mut() {
            if let Some(&dep) = ins.get(*next) {
                *next += 1;
                let dep = taps[dep.0 as usize].base;
                if !is_comb(dep) || state[dep] == 2 {
                    continue;
                }
                if state[dep] == 1 {
                    return None;
                }
                state[dep] = 1;
                stack.push((dep, defs[dep].comb_inputs(), 0));
            } else {
                state[*node] = 2;
                order.push(*node);
                stack.pop();
            }
        }
    }
    Some(order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;
    use crate::rtl::sim::Sim;
    use crate::rtl::{Module, Sig};

    /// A random three-stage feed-forward module over narrow and wide signals, with every
    /// combinational definition kind and registers chained to various depths.
    fn random_pipeline(seed: u64) -> Module {
        let mut r = SplitMix64(seed);
        let mut m = Module::new("batch_check");
        let mut pool: Vec<Sig> = [Ty::s(13), Ty::s(13), Ty::u(9), Ty::u(9), Ty::s(40), Ty::s(40), Ty::u(63), Ty::s(64), Ty::u(64), Ty::s(90), Ty::s(90)]
            .iter()
            .enumerate()
            .map(|(i, t)| m.input(&format!("in{i}"), *t))
            .collect();
        let k = m.konst("k", Ty::u(9), 300);
        pool.push(k);
        for stage in 0..3 {
            let mut next = Vec::new();
            for j in 0..24 {
                let a = pool[r.next_u64() as usize % pool.len()];
                let same: Vec<Sig> = pool.iter().copied().filter(|x| x.ty == a.ty && x.id != a.id).collect();
                let b = if same.is_empty() { a } else { same[r.next_u64() as usize % same.len()] };
                let name = format!("op{stage}_{j}");
                let s = match r.next_u64() % 14 {
                    0 => m.add(&name, a, b),
                    1 => m.sub(&name, a, b),
                    2 => m.bin(&name, BinOp::Xor, a, b),
                    3 if a.ty.width * 2 <= 128 => m.mul(&name, a, b),
                    4 => m.bin(&name, BinOp::Lt, a, b),
                    5 => m.bin(&name, BinOp::Le, a, b),
                    6 => m.un(&name, UnOp::Neg, a),
                    7 => m.un(&name, UnOp::Not, a),
                    8 if a.ty.width > 1 => m.shr(&name, a, 1 + (r.next_u64() % (a.ty.width as u64 - 1)) as u32),
                    9 => m.shl(&name, a, (r.next_u64() % a.ty.width as u64) as u32),
                    10 => m.resize(&name, a, 1 + (r.next_u64() % 100) as u32),
                    11 => {
                        let sel = m.bit(&format!("{name}_sel"), a, 0);
                        m.mux(&name, sel, b, a)
                    }
                    12 if a.ty.width >= 3 => {
                        let sel = m.slice(&format!("{name}_sel"), a, 1, 2);
                        m.case(&name, sel, &[(0, a), (2, b)], b)
                    }
                    _ if a.ty.width + 9 <= 128 => m.concat(&name, &[a, k]),
                    _ => m.un(&name, UnOp::AsUnsigned, a),
                };
                let depth = 1 + r.next_u64() % 3;
                let mut d = s;
                for i in 0..depth {
                    d = m.delay(&format!("{name}_d{i}"), d);
                }
                next.push(d);
                if r.next_u64() % 3 == 0 {
                    m.output(&format!("o{stage}_{j}"), d);
                }
            }
            pool.extend(next);
        }
        m
    }

    #[test]
    fn batches_match_the_cycle_simulator() {
        for seed in 0..12 {
            let m = random_pipeline(seed);
            let mut sim = Sim::new(&m);
            let mut batch = BatchSim::new(&m, 37).expect("feed-forward");
            let ins: Vec<Sig> = m.inputs.iter().map(|&i| m.handle(i)).collect();
            let outs: Vec<Sig> = m.outputs.iter().map(|(_, i)| m.handle(*i)).collect();
            let mut r = SplitMix64(seed + 100);
            let cycles = 300;
            let stim: Vec<Vec<i128>> = (0..cycles)
                .map(|_| ins.iter().map(|s| s.ty.value(s.ty.wrap(((r.next_u64() as i128) << 64) | r.next_u64() as i128))).collect())
                .collect();
            let mut want = Vec::new();
            for st in &stim {
                for (s, v) in ins.iter().zip(st) {
                    sim.set(*s, *v);
                }
                sim.tick();
                want.push(outs.iter().map(|o| sim.get(*o)).collect::<Vec<_>>());
            }
            let mut got = vec![vec![0i128; outs.len()]; cycles];
            batch.run(cycles, |c, k| stim[c][k], |c, k, v| got[c][k] = v);
            for c in 0..cycles {
                assert_eq!(got[c], want[c], "seed {seed}, cycle {c}");
            }
        }
    }

    #[test]
    fn signed_sub() {
        let mut m = Module::new("s");
        let a = m.input("a", Ty::s(13));
        let b = m.input("b", Ty::s(13));
        let d = m.sub("d", a, b);
        let q = m.delay("q", d);
        m.output("q", q);
        let mut batch = BatchSim::new(&m, 4).unwrap();
        let mut got = vec![0; 6];
        batch.run(6, |c, k| if k == 0 { c as i128 } else { 3 }, |c, _, v| got[c] = v);
        assert_eq!(got, vec![-3, -2, -1, 0, 1, 2]);
    }

    #[test]
    fn feedback_and_enables_are_declined() {
        let mut m = Module::new("counter");
        let r = m.reg("count", Ty::u(8), None);
        let one = m.konst("one", Ty::u(8), 1);
        let n = m.add("next", r, one);
        m.connect(r, n, None);
        m.output("q", r);
        assert!(BatchSim::new(&m, 8).is_none());
    }
}
