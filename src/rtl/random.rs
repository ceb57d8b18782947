//! Random netlists for the agreement property: every operator, signed and unsigned, `case`
//! with signed and unsigned selectors, concatenations, delay lines, registers with and without
//! enable and reset fed back through arbitrary logic, a ROM and a RAM. Every simulator and
//! printer must give such a module the same meaning, cycle for cycle (tests/rtl_agree.rs).
//!
//! Outputs are registered, so the batched simulator (which observes after the clock edge and
//! declines combinational input-to-output paths) can run every generated module.

use super::batch::BatchSim;
use super::netlist::{Module, Sig};
use super::sim::Sim;
use super::width::{BinOp, Ty, UnOp};
use crate::rng::SplitMix64;

/// Limits of a generated module.
#[derive(Clone, Copy, Debug)]
pub struct Shape {
    /// Widest signal (≤ 128); HDL testbenches are run with ≤ 64.
    pub max_width: u32,
    /// Combinational nodes.
    pub nodes: usize,
}

struct Gen<'a> {
    m: &'a mut Module,
    r: SplitMix64,
    pool: Vec<Sig>,
    max: u32,
}

impl Gen<'_> {
    fn pick(&mut self) -> Sig {
        self.pool[self.r.below(self.pool.len() as u64) as usize]
    }

    fn ty(&mut self) -> Ty {
        // Mostly narrow, with the edges of the batched kernels (63, 64, 65, 127, 128) in reach.
        let w = match self.r.below(10) {
            0 => [1, 2, 63, 64, 65, 127, 128][self.r.below(7) as usize].min(self.max),
            1..=5 => 1 + self.r.below(8) as u32,
            _ => 1 + self.r.below(self.max as u64) as u32,
        };
        Ty { width: w, signed: self.r.below(2) == 1 }
    }

    /// `s` as type `t`: resized and reinterpreted (two nodes at most).
    fn to_ty(&mut self, s: Sig, t: Ty) -> Sig {
        let mut s = s;
        if s.ty.width != t.width {
            s = self.m.resize("fit", s, t.width);
        }
        if s.ty.signed != t.signed {
            s = self.m.un("cast", if t.signed { UnOp::AsSigned } else { UnOp::AsUnsigned }, s);
        }
        s
    }

    fn konst(&mut self, t: Ty) -> Sig {
        let bits = ((self.r.next_u64() as u128) << 64 | self.r.next_u64() as u128) & t.mask();
        // Edge values now and then: 0, all ones, the sign bit alone.
        let bits = match self.r.below(4) {
            0 => 0,
            1 => t.mask(),
            2 => 1u128 << (t.width - 1),
            _ => bits,
        };
        self.m.konst("k", t, t.value(bits))
    }

    fn node(&mut self) -> Sig {
        let a = self.pick();
        let bin =
            [BinOp::Add, BinOp::Sub, BinOp::And, BinOp::Or, BinOp::Xor, BinOp::Eq, BinOp::Ne, BinOp::Lt, BinOp::Le];
        match self.r.below(16) {
            0..=4 => {
                let op = bin[self.r.below(bin.len() as u64) as usize];
                let b = if self.r.below(5) == 0 { self.konst(a.ty) } else { self.pick() };
                let b = self.to_ty(b, a.ty);
                self.m.bin("op", op, a, b)
            }
            5 => {
                let b = self.pick();
                let b = self.to_ty(b, Ty { width: b.ty.width.min(128 - a.ty.width).max(1), signed: a.ty.signed });
                if a.ty.width + b.ty.width > 128 {
                    return a;
                }
                self.m.bin("mul", BinOp::Mul, a, b)
            }
            6 => self.m.un("not", UnOp::Not, a),
            7 => self.m.un("neg", UnOp::Neg, a),
            8 if a.ty.width > 1 => {
                let k = 1 + self.r.below(a.ty.width as u64 - 1) as u32;
                let op = if self.r.below(2) == 0 { UnOp::Shl(k) } else { UnOp::Shr(k) };
                self.m.un("sh", op, a)
            }
            9 => {
                let lsb = self.r.below(a.ty.width as u64) as u32;
                let w = 1 + self.r.below((a.ty.width - lsb) as u64) as u32;
                self.m.slice("slice", a, lsb, w)
            }
            10 => {
                let w = 1 + self.r.below(self.max as u64) as u32;
                self.m.resize("resize", a, w)
            }
            11 => self.m.un("cast", if a.ty.signed { UnOp::AsUnsigned } else { UnOp::AsSigned }, a),
            12 => {
                let sel = self.pick();
                let sel = self.m.bit("sel", sel, 0);
                let b = self.pick();
                let b = self.to_ty(b, a.ty);
                self.m.mux("mux", sel, a, b)
            }
            13 => self.case(a),
            14 => {
                let parts: Vec<Sig> = (0..2 + self.r.below(3)).map(|_| self.pick()).collect();
                let mut keep = Vec::new();
                let mut w = 0;
                for p in parts {
                    if w + p.ty.width <= self.max {
                        w += p.ty.width;
                        keep.push(p);
                    }
                }
                if keep.is_empty() { a } else { self.m.concat("cat", &keep) }
            }
            _ => {
                let depth = 2 + self.r.below(4) as u32;
                self.m.delay_line("late", a, depth)
            }
        }
    }

    /// A case over a selector of 1–6 bits, signed or not, with distinct arm patterns.
    fn case(&mut self, default: Sig) -> Sig {
        let s = self.pick();
        let w = (1 + self.r.below(6) as u32).min(s.ty.width);
        let sel = self.m.slice("sel", s, 0, w);
        let sel = if self.r.below(2) == 1 { self.m.un("sel_s", UnOp::AsSigned, sel) } else { sel };
        let mut arms = Vec::new();
        for v in 0..(1u128 << w) {
            if self.r.below(2) == 0 {
                let x = self.pick();
                arms.push((v, self.to_ty(x, default.ty)));
            }
        }
        self.m.case("case", sel, &arms, default)
    }
}

/// A random module of the given shape, the same for the same seed.
pub fn random_module(seed: u64, shape: Shape) -> Module {
    random_named("agree", seed, shape, true)
}

/// `random_module` with a name, and with an instance of a smaller random module in it when
/// `nested`.
fn random_named(name: &str, seed: u64, shape: Shape, nested: bool) -> Module {
    let mut m = Module::new(name);
    let mut g = Gen { m: &mut m, r: SplitMix64(seed), pool: Vec::new(), max: shape.max_width.clamp(8, 128) };
    for i in 0..1 + g.r.below(3) {
        let t = g.ty();
        let s = g.m.input(&format!("in{i}"), t);
        g.pool.push(s);
    }
    // Registers first, so logic can read them (feedback); their inputs are chosen at the end.
    let mut regs = Vec::new();
    for _ in 0..1 + g.r.below(3) {
        let t = g.ty();
        let reset = if g.r.below(2) == 0 { Some(t.value(g.r.next_u64() as u128 & t.mask())) } else { None };
        let r = g.m.reg("state", t, reset);
        regs.push(r);
        g.pool.push(r);
    }
    // A ROM read and a RAM read, their addresses from the pool (so possibly in a loop).
    let (rom, ram) = (g.r.below(2) == 0, g.r.below(2) == 0);
    let mut ram_port = None;
    if rom {
        let t = g.ty();
        let words = (0..3 + g.r.below(6)).map(|_| g.r.next_u64() as u128 & t.mask()).collect();
        let k = g.m.rom("table", t.width, words);
        let a = g.pick();
        let a = g.to_ty(a, Ty::u(crate::bits::rom_addr_bits(g.m.roms[k].words.len())));
        let q = g.m.rom_read("rom_q", k, a);
        g.pool.push(q);
    }
    if ram {
        let t = g.ty();
        let words = (0..2 + g.r.below(5)).map(|_| g.r.next_u64() as u128 & t.mask()).collect();
        let k = g.m.ram("mem", t.width, words);
        let bits = crate::bits::rom_addr_bits(g.m.roms[k].words.len());
        let a = g.pick();
        let a = g.to_ty(a, Ty::u(bits));
        let q = g.m.rom_read("ram_q", k, a);
        g.pool.push(q);
        ram_port = Some((k, bits, t.width));
    }
    // A wire (a forward reference), driven at the end by a register, so it makes no loop.
    let wire_ty = g.ty();
    let wire = g.m.wire("fwd", wire_ty);
    g.pool.push(wire);
    // Now and then an instance of a smaller random module (hierarchy and flattening).
    if nested && g.r.below(3) == 0 {
        let sub = std::rc::Rc::new(random_named("agree_sub", seed ^ 0xA5A5, Shape { nodes: 6, ..shape }, false));
        let ins: Vec<Sig> = sub
            .inputs
            .iter()
            .map(|&i| {
                let x = g.pick();
                g.to_ty(x, sub.sig(i).ty)
            })
            .collect();
        let outs = g.m.instance("u_sub", &sub, &ins);
        g.pool.extend(outs);
    }
    let mut outs = Vec::new();
    for _ in 0..shape.nodes {
        let s = g.node();
        g.pool.push(s);
        outs.push(s);
    }
    let driver = g.to_ty(regs[0], wire_ty);
    g.m.drive(wire, driver);
    for r in regs {
        let next = g.pick();
        let next = g.to_ty(next, r.ty);
        let enable = if g.r.below(2) == 0 {
            let e = g.pick();
            Some(g.m.bit("enable", e, 0))
        } else {
            None
        };
        g.m.connect(r, next, enable);
    }
    if let Some((k, bits, width)) = ram_port {
        let (we, a, d) = (g.pick(), g.pick(), g.pick());
        let we = g.m.bit("we", we, 0);
        let a = g.to_ty(a, Ty::u(bits));
        let d = g.to_ty(d, Ty::u(width));
        g.m.ram_write(k, we, a, d);
    }
    // Registered outputs: the last nodes and a few random ones.
    let n = outs.len();
    let mut chosen: Vec<Sig> = outs[n.saturating_sub(3)..].to_vec();
    for _ in 0..2 {
        chosen.push(g.pick());
    }
    for (i, s) in chosen.into_iter().enumerate() {
        let r = g.m.delay("out_r", s);
        g.m.output(&format!("out{i}"), r);
    }
    m
}

/// Random input values for `m`, cycle by cycle (edge values now and then).
pub fn random_inputs(m: &Module, seed: u64, cycles: usize) -> Vec<Vec<i128>> {
    let mut r = SplitMix64(seed ^ 0x5EED);
    (0..cycles)
        .map(|_| {
            m.inputs
                .iter()
                .map(|&i| {
                    let t = m.sig(i).ty;
                    let bits = match r.below(6) {
                        0 => 0,
                        1 => t.mask(),
                        2 => 1u128 << (t.width - 1),
                        _ => ((r.next_u64() as u128) << 64 | r.next_u64() as u128) & t.mask(),
                    };
                    t.value(bits)
                })
                .collect()
        })
        .collect()
}

/// Every output of every cycle from `Sim` and from `BatchSim` (batch size `batch`); the first
/// difference as text.
pub fn sim_vs_batch(m: &Module, inputs: &[Vec<i128>], batch: usize) -> Result<(), String> {
    let mut sim = Sim::new(m);
    let ins: Vec<_> = m.inputs.iter().map(|&i| m.handle(i)).collect();
    let outs: Vec<_> = m.outputs.iter().map(|(_, i)| m.handle(*i)).collect();
    let mut want = Vec::with_capacity(inputs.len());
    for cycle in inputs {
        for (s, v) in ins.iter().zip(cycle) {
            sim.set(*s, *v);
        }
        sim.tick();
        want.push(outs.iter().map(|o| sim.get(*o)).collect::<Vec<_>>());
    }
    let mut b = BatchSim::new(m, batch).ok_or("BatchSim declined a design with registered outputs")?;
    let mut got = vec![vec![0i128; outs.len()]; inputs.len()];
    b.run(inputs.len(), |c, k| inputs[c][k], |c, k, v| got[c][k] = v);
    match want.iter().zip(&got).position(|(w, g)| w != g) {
        None => Ok(()),
        Some(c) => Err(format!("cycle {c}: Sim {:?}, BatchSim {:?}", want[c], got[c])),
    }
}

/// The agreement property on the random netlists of `seeds` (24 cycles each, batch sizes 1,
/// 3, 7 and 64 in turn): the failing seeds with their first difference. `done` is called
/// after each netlist (for a progress bar).
pub fn agree(seeds: std::ops::Range<u64>, done: &dyn Fn()) -> Vec<String> {
    let mut failures = Vec::new();
    for seed in seeds {
        let m = random_module(seed, Shape { max_width: 128, nodes: 14 });
        let batch = [1, 3, 7, 64][(seed % 4) as usize];
        if let Err(e) = sim_vs_batch(&m, &random_inputs(&m, seed, 24), batch) {
            failures.push(format!("seed {seed} (batch {batch}): {e}"));
        }
        done();
    }
    failures
}
