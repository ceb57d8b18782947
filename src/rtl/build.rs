//! The typed builder: signal handles with operators over the same netlist. A core reads like
//! the circuit it is — `(plane - o).xmul(inv) >> c`, `tmin.le(near_max)` — while every type
//! still comes from `width.rs`. Operators that keep the width (`+ - & | ^ ! <<k >>k`, wrapping
//! like the hardware) use Rust's operators; the ones that grow have their own names (`xmul`,
//! `xsigned`, `resize`), so growth is always visible. Integer operands are constants typed from
//! the other operand. Nodes get deterministic, readable names from their operands
//! (`tmin_lt_tmax`), or a numbered one when that would be long; `name()` gives the name a
//! person wants. Two constant operands fold into a constant by `Def::eval`.

use super::netlist::{BlockKind, Def, Module, Sig};
use super::width::{BinOp, Ty, UnOp, bin_ty, un_ty};
use std::cell::{Cell, RefCell};
use std::ops;
use std::rc::Rc;

/// Delay lines of this many clocks or more are LUT-RAM rings (`Builder::delay_line`): below,
/// a ring's pointers and read register cost about what the flip-flops they save do.
pub const RING_FROM: u32 = 8;
/// The widest slice of a ring with pointers of its own: each pointer drives RING_SLICE / 4
/// DPR16X4s on an ECP5, so a wide line does not hang on one address net.
pub const RING_SLICE: u32 = 32;

/// Builds one module. Handles borrow it, so operators need no `&mut`.
pub struct Builder {
    m: RefCell<Module>,
    counter: Cell<u32>,
    /// Signals whose name is only a number (`plus_7`), which a stage may name after its field.
    numbered: RefCell<std::collections::BTreeSet<u32>>,
    /// Signals the builder named (operator results): `name()` may rename these in place.
    auto_named: RefCell<std::collections::BTreeSet<u32>>,
    /// Constants made so far, by (type, bits): each value of a type is one signal.
    konsts: RefCell<std::collections::BTreeMap<(u32, bool, u128), Sig>>,
}

/// A signal handle: the signal and the builder it belongs to.
#[derive(Clone, Copy)]
pub struct S<'b> {
    pub b: &'b Builder,
    pub sig: Sig,
}

impl std::fmt::Debug for S<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {:?}", self.b.name_of(self.sig), self.sig.ty)
    }
}

/// Longest operand-derived name; longer ones become `{op}_{k}`.
const NAME_MAX: usize = 24;

impl Builder {
    pub fn new(name: &str) -> Builder {
        Builder {
            m: RefCell::new(Module::new(name)),
            counter: Cell::new(0),
            numbered: Default::default(),
            auto_named: Default::default(),
            konsts: Default::default(),
        }
    }

    /// The finished module (checked: every register and wire is driven).
    pub fn finish(self) -> Module {
        let m = self.m.into_inner();
        m.check().unwrap_or_else(|e| panic!("{e}"));
        m
    }

    /// Direct access to the netlist, for what the handles do not cover.
    pub fn with<R>(&self, f: impl FnOnce(&mut Module) -> R) -> R {
        f(&mut self.m.borrow_mut())
    }

    pub fn s(&self, sig: Sig) -> S<'_> {
        S { b: self, sig }
    }

    pub fn name_of(&self, s: Sig) -> String {
        self.m.borrow().sig(s.id).name.clone()
    }

    /// A name from operand names, or `{op}_{k}` when that would be long.
    fn auto(&self, op: &str, parts: &[&str]) -> String {
        // The next signal made gets this name.
        let next = self.m.borrow().signals.len() as u32;
        self.auto_named.borrow_mut().insert(next);
        let joined = parts.join(&format!("_{op}_"));
        if !parts.is_empty() && joined.len() <= NAME_MAX {
            return if parts.len() == 1 { format!("{op}_{joined}") } else { joined };
        }
        let k = self.counter.get();
        self.counter.set(k + 1);
        self.numbered.borrow_mut().insert(next);
        format!("{op}_{k}")
    }

    /// Whether a signal still has a numbered name (`plus_7`), not one from its operands or a
    /// person.
    pub fn is_numbered(&self, s: Sig) -> bool {
        self.numbered.borrow().contains(&s.id.0)
    }

    pub fn input(&self, name: &str, ty: Ty) -> S<'_> {
        self.s(self.m.borrow_mut().input(name, ty))
    }

    pub fn output(&self, name: &str, s: S<'_>) {
        self.m.borrow_mut().output(name, s.sig);
    }

    /// A constant with a name of its own (not shared with other users of its value).
    pub fn konst_named(&self, name: &str, ty: Ty, v: i128) -> S<'_> {
        self.s(self.m.borrow_mut().konst(name, ty, v))
    }

    /// A constant of type `ty`, named after its value (one signal per type and value).
    pub fn konst(&self, ty: Ty, v: i128) -> S<'_> {
        let key = (ty.width, ty.signed, ty.wrap(v));
        if let Some(&s) = self.konsts.borrow().get(&key) {
            return self.s(s);
        }
        let name = if v < 0 { format!("k_m{}", v.unsigned_abs()) } else { format!("k_{v}") };
        let s = self.m.borrow_mut().konst(&name, ty, v);
        self.konsts.borrow_mut().insert(key, s);
        self.s(s)
    }

    /// A register of type `ty` (with a synchronous reset value, or none). Its input is given
    /// by `next`, `next_when`, or a state machine.
    pub fn reg(&self, name: &str, ty: Ty, reset: Option<i128>) -> S<'_> {
        self.s(self.m.borrow_mut().reg(name, ty, reset))
    }

    /// A wire, driven later with `drive` (combinational feedback).
    pub fn wire(&self, name: &str, ty: Ty) -> S<'_> {
        self.s(self.m.borrow_mut().wire(name, ty))
    }

    pub fn drive(&self, wire: S<'_>, src: S<'_>) {
        self.m.borrow_mut().drive(wire.sig, src.sig);
    }

    /// `reg` loads `next` every clock.
    pub fn next(&self, reg: S<'_>, next: S<'_>) {
        self.m.borrow_mut().connect(reg.sig, next.sig, None);
    }

    /// Opens the named stage of a hand-built core (a ring stage, a port, an arbiter), closing
    /// the one before: the signals made until the next `stage` or `end_stage` belong to it, and
    /// the printers lay them out together under a comment `stage {name}: {doc}`, with one
    /// clocked process for its registers, as a `Pipeline`'s stages are. It changes how the HDL
    /// reads, never the circuit.
    pub fn stage(&self, name: &str, doc: &str) {
        self.end_stage();
        self.m.borrow_mut().begin_block(name, doc, BlockKind::Stage);
    }

    /// Closes the stage `stage` opened (the signals made next belong to none).
    pub fn end_stage(&self) {
        let mut m = self.m.borrow_mut();
        if let Some(open) = m.current_block {
            assert!(matches!(m.blocks[open].kind, BlockKind::Stage), "{}: a stage inside a state machine", m.name);
            m.end_block();
        }
    }

    /// `k` copies of register `reg` (its input already given): registers `{reg}_c1`, … that
    /// load what it loads, with its reset, so they always hold its value. Each drives part of
    /// a fan-out too wide for one net (a LUT-RAM's read address across a hundred RAM slices);
    /// the printers tell synthesis not to merge them (`BlockKind::Copies`).
    pub fn copies(&self, reg: S<'_>, k: usize) -> Vec<S<'_>> {
        let copies = self.m.borrow_mut().copies(reg.sig, k);
        copies.into_iter().map(|s| self.s(s)).collect()
    }

    /// `reg` loads `next` in the clocks where `enable` is 1.
    pub fn next_when(&self, reg: S<'_>, enable: S<'_>, next: S<'_>) {
        self.m.borrow_mut().connect(reg.sig, next.sig, Some(enable.sig));
    }

    /// `x` one clock later, in a register named `name`.
    pub fn delay(&self, name: &str, x: S<'_>) -> S<'_> {
        self.s(self.m.borrow_mut().delay(name, x.sig))
    }

    /// `x` one clock later in a register `rst` clears: a valid bit.
    pub fn valid_delay(&self, name: &str, x: S<'_>) -> S<'_> {
        self.valid_line(name, x, 1)
    }

    /// `x` `depth` clocks later in registers `rst` clears: a valid bit (`Module::valid_line`).
    pub fn valid_line(&self, name: &str, x: S<'_>, depth: u32) -> S<'_> {
        self.s(self.m.borrow_mut().valid_line(name, x.sig, depth))
    }

    /// `x` `depth` clocks later: a shift register, or from `RING_FROM` clocks a ring in LUT
    /// RAM (`ring`), cycle for cycle the same.
    pub fn delay_line<'b>(&'b self, name: &str, x: S<'b>, depth: u32) -> S<'b> {
        if depth < RING_FROM {
            return self.s(self.m.borrow_mut().delay_line(name, x.sig, depth));
        }
        let w = x.width();
        let parts: Vec<S<'b>> = (0..w.div_ceil(RING_SLICE))
            .rev()
            .map(|k| {
                let lo = k * RING_SLICE;
                let part = if w <= RING_SLICE { name.to_string() } else { format!("{name}_p{k}") };
                self.ring(&part, x.slice(lo, RING_SLICE.min(w - lo)), depth)
            })
            .collect();
        let bits = if parts.len() == 1 { parts[0] } else { self.cat(&parts) };
        if x.ty().signed { bits.signed() } else { bits }
    }

    /// Unsigned `x` `depth` (≥ 2) clocks later through a LUT RAM of `rom_depth(depth)` words
    /// written every clock at `wp` and read (registered) at `rp` = `wp` − (`depth` − 1): a
    /// word is read `depth` − 1 clocks after its write, and the read register adds the last
    /// clock. `rp` is a register loaded from `wp` (a constant add), so it matches `wp` from
    /// the first clock on; the words never written read as 0, like a shift register's
    /// initial contents, and neither pointer is reset, so a reset leaves the line's data as a
    /// shift register's. A flip-flop per bit and clock costs an ECP5 a whole FF; 16 clocks of
    /// 4 bits fit one DPR16X4.
    fn ring<'b>(&'b self, name: &str, x: S<'b>, depth: u32) -> S<'b> {
        let words = crate::bits::rom_depth(depth as usize);
        let k = crate::bits::rom_addr_bits(words);
        let wp = self.reg(&format!("{name}_wp"), Ty::u(k), None);
        let rp = self.reg(&format!("{name}_rp"), Ty::u(k), None);
        self.next(wp, wp + 1);
        let back = (words as i128 + 2 - depth as i128).rem_euclid(words as i128);
        self.next(rp, wp + back);
        let mem = self.ram(&format!("{name}_mem"), x.width(), vec![0; words]);
        self.ram_write(mem, self.konst(Ty::BIT, 1), wp, x);
        self.read(name, mem, rp)
    }

    /// `sel ? t : f`; `sel` is one bit.
    pub fn mux<'b>(&'b self, sel: S<'b>, t: S<'b>, f: S<'b>) -> S<'b> {
        let name = self.auto("mux", &[&self.name_of(sel.sig)]);
        self.s(self.m.borrow_mut().mux(&name, sel.sig, t.sig, f.sig))
    }

    /// The arm whose pattern equals `sel`'s bits, else `default`.
    pub fn case<'b>(&'b self, sel: S<'b>, arms: &[(u128, S<'b>)], default: S<'b>) -> S<'b> {
        let name = self.auto("case", &[&self.name_of(sel.sig)]);
        let arms: Vec<(u128, Sig)> = arms.iter().map(|(v, s)| (*v, s.sig)).collect();
        self.s(self.m.borrow_mut().case(&name, sel.sig, &arms, default.sig))
    }

    /// Concatenation, most significant first; unsigned.
    pub fn cat<'b>(&'b self, parts: &[S<'b>]) -> S<'b> {
        let sigs: Vec<Sig> = parts.iter().map(|p| p.sig).collect();
        let name = self.auto("cat", &[]);
        self.s(self.m.borrow_mut().concat(&name, &sigs))
    }

    /// `v[sel]` for a 2-bit axis number (3 picks `v[0]`; it never occurs).
    pub fn pick<'b>(&'b self, sel: S<'b>, v: [S<'b>; 3]) -> S<'b> {
        self.case(sel, &[(1, v[1]), (2, v[2])], v[0])
    }

    pub fn rom(&self, name: &str, width: u32, words: Vec<u128>) -> usize {
        self.m.borrow_mut().rom(name, width, words)
    }

    pub fn ram(&self, name: &str, width: u32, init: Vec<u128>) -> usize {
        self.m.borrow_mut().ram(name, width, init)
    }

    pub fn ram_write(&self, mem: usize, we: S<'_>, addr: S<'_>, data: S<'_>) {
        self.m.borrow_mut().ram_write(mem, we.sig, addr.sig, data.sig);
    }

    /// The word of memory `mem` at `addr`, one clock later.
    pub fn read(&self, name: &str, mem: usize, addr: S<'_>) -> S<'_> {
        self.s(self.m.borrow_mut().rom_read(name, mem, addr.sig))
    }

    /// Instantiates `sub`; its outputs by port name.
    pub fn instance<'b>(&'b self, label: &str, sub: &Rc<Module>, inputs: &[S<'b>]) -> Ports<'b> {
        let ins: Vec<Sig> = inputs.iter().map(|s| s.sig).collect();
        let outs = self.m.borrow_mut().instance(label, sub, &ins);
        Ports {
            names: sub.outputs.iter().map(|o| o.0.clone()).collect(),
            sigs: outs.into_iter().map(|s| self.s(s)).collect(),
        }
    }

    /// Instantiates `sub` with its inputs bound by port name (each exactly once, in any
    /// order); its outputs by port name.
    pub fn instance_named<'b>(&'b self, label: &str, sub: &Rc<Module>, bind: &[(&str, S<'b>)]) -> Ports<'b> {
        let ports: Vec<&str> = sub.inputs.iter().map(|&i| sub.sig(i).name.as_str()).collect();
        for (k, (port, _)) in bind.iter().enumerate() {
            assert!(ports.contains(port), "{label}: {} has no input port {port}", sub.name);
            assert!(!bind[..k].iter().any(|(p, _)| p == port), "{label}: input port {port} bound twice");
        }
        let inputs: Vec<S<'b>> = ports
            .iter()
            .map(|port| bind.iter().find(|(p, _)| p == port).unwrap_or_else(|| panic!("{label}: {port} unbound")).1)
            .collect();
        self.instance(label, sub, &inputs)
    }

    fn bin<'b>(&'b self, op: BinOp, a: S<'b>, b: S<'b>, sym: &str) -> S<'b> {
        let ty = bin_ty(op, a.sig.ty, b.sig.ty).unwrap_or_else(|e| panic!("{}: {op:?}: {e}", self.m.borrow().name));
        if let Some(k) = self.fold(&Def::Bin(op, a.sig.id, b.sig.id), &[a.sig, b.sig], ty) {
            return k;
        }
        let name = self.auto(sym, &[&self.name_of(a.sig), &self.name_of(b.sig)]);
        self.s(self.m.borrow_mut().bin(&name, op, a.sig, b.sig))
    }

    fn un<'b>(&'b self, op: UnOp, a: S<'b>, sym: &str) -> S<'b> {
        let ty = un_ty(op, a.sig.ty).unwrap_or_else(|e| panic!("{}: {op:?}: {e}", self.m.borrow().name));
        if let Some(k) = self.fold(&Def::Un(op, a.sig.id), &[a.sig], ty) {
            return k;
        }
        let name = self.auto(sym, &[&self.name_of(a.sig)]);
        self.s(self.m.borrow_mut().un(&name, op, a.sig))
    }

    /// Constant folding: an operator on constants is the constant `Def::eval` gives.
    fn fold(&self, def: &Def, ops: &[Sig], ty: Ty) -> Option<S<'_>> {
        let bits: Option<Vec<u128>> = {
            let m = self.m.borrow();
            ops.iter().map(|s| if let Def::Const(v) = m.sig(s.id).def { Some(v) } else { None }).collect()
        };
        let tys: Vec<Ty> = ops.iter().map(|s| s.ty).collect();
        let v = def.eval(&tys, &bits?, ty);
        Some(self.konst(ty, ty.value(v)))
    }
}

/// The outputs of an instance, by port name.
pub struct Ports<'b> {
    names: Vec<String>,
    sigs: Vec<S<'b>>,
}

impl<'b> Ports<'b> {
    pub fn get(&self, port: &str) -> S<'b> {
        let k = self.names.iter().position(|n| n == port).unwrap_or_else(|| panic!("no output port {port}"));
        self.sigs[k]
    }
    pub fn all(&self) -> &[S<'b>] {
        &self.sigs
    }
}

impl<'b> S<'b> {
    pub fn ty(self) -> Ty {
        self.sig.ty
    }
    pub fn width(self) -> u32 {
        self.sig.ty.width
    }

    /// Gives the signal the name a person wants (made unique and legal). A node the builder
    /// made and named is renamed in place; anything else — a port, a register, a shared
    /// constant, the operand an identity operation handed back — keeps its name, and the
    /// result is a named copy (a constant of its own, or a wire).
    pub fn name(self, name: &str) -> S<'b> {
        let b = self.b;
        if b.auto_named.borrow_mut().remove(&self.sig.id.0) {
            b.with(|m| m.rename(self.sig.id, name));
            b.numbered.borrow_mut().remove(&self.sig.id.0);
            return self;
        }
        if let super::netlist::Def::Const(v) = b.with(|m| m.sig(self.sig.id).def.clone()) {
            return b.konst_named(name, self.ty(), self.ty().value(v));
        }
        let w = b.wire(name, self.ty());
        b.drive(w, self);
        w
    }

    /// A constant of this signal's type.
    pub fn k(self, v: i128) -> S<'b> {
        self.b.konst(self.sig.ty, v)
    }

    /// To `w` bits: sign- or zero-extended by signedness, or the low bits kept.
    pub fn resize(self, w: u32) -> S<'b> {
        if w == self.width() { self } else { self.b.un(UnOp::Resize(w), self, "rs") }
    }
    /// Bits [lsb, lsb + w) as unsigned.
    pub fn slice(self, lsb: u32, w: u32) -> S<'b> {
        if lsb == 0 && w == self.width() && !self.ty().signed {
            return self;
        }
        self.b.un(UnOp::Slice { lsb, width: w }, self, "bits")
    }
    pub fn bit(self, i: u32) -> S<'b> {
        self.slice(i, 1)
    }
    /// The sign bit.
    pub fn msb(self) -> S<'b> {
        self.bit(self.width() - 1)
    }
    /// The same bits read as signed / unsigned.
    pub fn signed(self) -> S<'b> {
        if self.ty().signed { self } else { self.b.un(UnOp::AsSigned, self, "s") }
    }
    pub fn unsigned(self) -> S<'b> {
        if self.ty().signed { self.b.un(UnOp::AsUnsigned, self, "u") } else { self }
    }
    /// An unsigned value as signed, one bit wider (its value unchanged).
    pub fn xsigned(self) -> S<'b> {
        assert!(!self.ty().signed, "xsigned of a signed value");
        self.resize(self.width() + 1).signed()
    }
    /// The full product: wa + wb bits.
    pub fn xmul(self, o: S<'b>) -> S<'b> {
        self.b.bin(BinOp::Mul, self, o, "x")
    }
    /// A comparison giving one bit; `swap` compares the other way round (`gt` is `lt` swapped).
    fn compare(self, op: BinOp, o: impl Operand<'b>, swap: bool) -> S<'b> {
        let o = o.as_sig(self);
        let sym = format!("{op:?}").to_lowercase();
        if swap { self.b.bin(op, o, self, &sym) } else { self.b.bin(op, self, o, &sym) }
    }
    pub fn eq(self, o: impl Operand<'b>) -> S<'b> {
        self.compare(BinOp::Eq, o, false)
    }
    pub fn ne(self, o: impl Operand<'b>) -> S<'b> {
        self.compare(BinOp::Ne, o, false)
    }
    /// One bit per byte from the bottom (the last may be shorter): whether it is non-zero.
    /// A wide zero test cut where a register can go: each byte's OR is two LUT levels, and
    /// `x ≠ 0` is the OR of the result.
    pub fn nonzero_bytes(self) -> S<'b> {
        let (x, w) = (self.unsigned(), self.width());
        let bytes: Vec<S<'b>> = (0..w.div_ceil(8)).rev().map(|i| x.slice(8 * i, 8.min(w - 8 * i)).ne(0)).collect();
        self.b.cat(&bytes)
    }
    pub fn lt(self, o: impl Operand<'b>) -> S<'b> {
        self.compare(BinOp::Lt, o, false)
    }
    pub fn le(self, o: impl Operand<'b>) -> S<'b> {
        self.compare(BinOp::Le, o, false)
    }
    pub fn gt(self, o: impl Operand<'b>) -> S<'b> {
        self.compare(BinOp::Lt, o, true)
    }
    pub fn ge(self, o: impl Operand<'b>) -> S<'b> {
        self.compare(BinOp::Le, o, true)
    }
    /// `self ? t : f` for a one-bit `self` (`f` may be an integer, typed from `t`).
    pub fn select(self, t: S<'b>, f: impl Operand<'b>) -> S<'b> {
        let f = f.as_sig(t);
        self.b.mux(self, t, f)
    }
    /// The smaller / larger of two signals of one type (ties take `self`).
    pub fn min(self, o: S<'b>) -> S<'b> {
        o.lt(self).select(o, self)
    }
    pub fn max(self, o: S<'b>) -> S<'b> {
        self.lt(o).select(o, self)
    }
}

/// A right operand: a signal, or an integer constant typed from the other operand.
pub trait Operand<'b> {
    fn as_sig(self, like: S<'b>) -> S<'b>;
}

impl<'b> Operand<'b> for S<'b> {
    fn as_sig(self, _: S<'b>) -> S<'b> {
        self
    }
}

impl<'b> Operand<'b> for i128 {
    fn as_sig(self, like: S<'b>) -> S<'b> {
        like.k(self)
    }
}

macro_rules! binop {
    ($tr:ident, $f:ident, $op:expr, $sym:literal) => {
        impl<'b, R: Operand<'b>> ops::$tr<R> for S<'b> {
            type Output = S<'b>;
            fn $f(self, o: R) -> S<'b> {
                let o = o.as_sig(self);
                self.b.bin($op, self, o, $sym)
            }
        }
    };
}
binop!(Add, add, BinOp::Add, "plus");
binop!(Sub, sub, BinOp::Sub, "minus");
binop!(BitAnd, bitand, BinOp::And, "and");
binop!(BitOr, bitor, BinOp::Or, "or");
binop!(BitXor, bitxor, BinOp::Xor, "xor");

impl<'b> ops::Not for S<'b> {
    type Output = S<'b>;
    fn not(self) -> S<'b> {
        self.b.un(UnOp::Not, self, "not")
    }
}
impl<'b> ops::Neg for S<'b> {
    type Output = S<'b>;
    fn neg(self) -> S<'b> {
        self.b.un(UnOp::Neg, self, "neg")
    }
}
/// Shift left by a constant, at the same width (bits shifted out are lost).
impl<'b> ops::Shl<u32> for S<'b> {
    type Output = S<'b>;
    fn shl(self, k: u32) -> S<'b> {
        if k == 0 { self } else { self.b.un(UnOp::Shl(k), self, "shl") }
    }
}
/// Shift right by a constant: arithmetic when signed, logical when unsigned.
impl<'b> ops::Shr<u32> for S<'b> {
    type Output = S<'b>;
    fn shr(self, k: u32) -> S<'b> {
        if k == 0 { self } else { self.b.un(UnOp::Shr(k), self, "shr") }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;

    #[test]
    fn operators_build_typed_nodes_with_readable_names() {
        let b = Builder::new("t");
        let x = b.input("x", Ty::s(8));
        let y = b.input("y", Ty::s(8));
        let lt = x.lt(y);
        assert_eq!(lt.ty(), Ty::BIT);
        assert_eq!(b.name_of(lt.sig), "x_lt_y");
        let p = x.xmul(y);
        assert_eq!(p.ty(), Ty::s(16));
        let z = ((x + 3) >> 1).name("half");
        assert_eq!(b.name_of(z.sig), "half");
        let o = lt.select(x, y);
        b.output("o", o);
        b.output("z", z);
        b.output("p", p);
        let m = b.finish();
        let mut sim = Sim::new(&m);
        let h = |i: usize| m.handle(m.inputs[i]);
        let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
        sim.set(h(0), -7);
        sim.set(h(1), 100);
        sim.eval();
        assert_eq!(sim.get(out("o")), -7);
        assert_eq!(sim.get(out("z")), -2);
        assert_eq!(sim.get(out("p")), -700);
    }

    /// Naming never renames a port or a shared constant: an identity operation's result and a
    /// shared constant get a named copy.
    #[test]
    fn naming_keeps_ports_and_shared_constants() {
        let b = Builder::new("t");
        let x = b.input("x", Ty::u(8));
        let y = x.resize(8).name("y");
        assert_eq!(b.name_of(x.sig), "x");
        assert_eq!(b.name_of(y.sig), "y");
        let k = b.konst(Ty::u(8), 5);
        let limit = k.name("limit");
        assert_ne!(k.sig, limit.sig);
        assert_eq!(b.name_of((x + 5).sig), "x_plus_k_5");
        let sum = (x + y).name("sum");
        assert_eq!(b.name_of(sum.sig), "sum");
    }

    /// A delay line from `RING_FROM` clocks is a LUT-RAM ring, and it shows what a shift
    /// register would, clock for clock from the first: 0 until the first value arrives, then
    /// every input `depth` clocks later, for lines narrower and wider than a ring slice, signed
    /// or not, at depths just under, at and over a power of two.
    #[test]
    fn a_ring_delays_exactly_as_a_shift_register() {
        for (depth, ty) in
            [(8, Ty::u(1)), (9, Ty::s(40)), (16, Ty::u(32)), (17, Ty::s(7)), (41, Ty::u(70)), (64, Ty::s(33))]
        {
            let b = Builder::new("t");
            let x = b.input("x", ty);
            let ring = b.delay_line("ring", x, depth);
            let shift = b.s(b.with(|m| m.delay_line("shift", x.sig, depth)));
            assert_eq!(ring.ty(), ty);
            b.output("ring", ring);
            b.output("shift", shift);
            let m = b.finish();
            let shift_lines = m.signals.iter().filter(|s| matches!(s.def, Def::DelayLine { .. })).count();
            assert_eq!((shift_lines, m.roms.len() as u32), (1, ty.width.div_ceil(RING_SLICE)), "rings in LUT RAM");
            let mut sim = Sim::new(&m);
            let (x, ring, shift) = (m.handle(m.inputs[0]), m.handle(m.outputs[0].1), m.handle(m.outputs[1].1));
            let mut rng = crate::rng::SplitMix64(depth as u64);
            for t in 0..3 * depth + 5 {
                sim.set(x, ty.value(ty.wrap(((rng.next_u64() as i128) << 64) | rng.next_u64() as i128)));
                sim.eval();
                assert_eq!(sim.get(ring), sim.get(shift), "depth {depth}, {ty:?}, clock {t}");
                sim.tick();
            }
        }
    }

    #[test]
    fn constants_fold() {
        let b = Builder::new("t");
        let k = b.konst(Ty::s(8), 100) + 100;
        assert!(matches!(b.with(|m| m.sig(k.sig.id).def.clone()), Def::Const(v) if Ty::s(8).value(v) == -56));
    }
}
