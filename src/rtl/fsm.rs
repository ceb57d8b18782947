//! The state-machine construct. The states are an enum (`states!`), whose order is the
//! encoding; width, encoding and names are derived from it once and used by the netlist, the
//! printers (named state constants, comments) and the simulators' per-state statistics.
//! Each state's whole behaviour is one block:
//!
//! ```text
//! fsm.state(St::Pop, |s| {
//!     s.when(sp_empty, |s| s.goto(St::Done)).otherwise(|s| {
//!         s.set(node, top_node);
//!         s.goto(St::Node);
//!     });
//! });
//! ```
//!
//! Assignments take effect at the clock edge; within a state they apply in program order and
//! the last one whose conditions hold wins; a register not assigned in a clock holds its value.
//! Every condition and value reads the registers as they are before the edge (as in a VHDL
//! process with signals): `s.set(count, count + 1)` followed by `s.when(count.eq(2), …)` tests
//! the old count.
//! `finish` builds each register's next value as a `case` on the state (one arm per state
//! that assigns it) and refuses a machine with a state that has no block. `is(state)` is a
//! one-hot flag register beside the binary state register (its value is the state compare's).

use super::build::{Builder, S};
use super::netlist::BlockKind;
use super::width::Ty;
use std::cell::RefCell;
use std::collections::BTreeMap;

/// An enum usable as the states of a machine: `ALL` in encoding order, and names.
pub trait States: Copy + Eq + std::fmt::Debug + 'static {
    const ALL: &'static [Self];
    fn name(self) -> &'static str;
    /// The state's encoding: its position in `ALL`.
    fn code(self) -> u128 {
        Self::ALL.iter().position(|&s| s == self).expect("a state of ALL") as u128
    }
    /// Bits of the state register.
    fn width() -> u32 {
        crate::bits::value_bits(Self::ALL.len().saturating_sub(1))
    }
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|s| s.name()).collect()
    }
}

/// Declares a states enum: `states! { pub enum St { Idle = "idle", Busy = "busy" } }`.
#[macro_export]
macro_rules! states {
    ($(#[$meta:meta])* $vis:vis enum $name:ident { $($(#[$vm:meta])* $v:ident = $label:literal),+ $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        $vis enum $name { $($(#[$vm])* $v),+ }
        impl $crate::rtl::fsm::States for $name {
            const ALL: &'static [Self] = &[$($name::$v),+];
            fn name(self) -> &'static str {
                match self { $($name::$v => $label),+ }
            }
        }
    };
}

/// A condition: a one-bit signal (by index) and the value it must have.
type Cond = (usize, bool);

/// One assignment: under these conditions, in this state, `target` gets `value`.
struct Assign {
    state: u128,
    conds: Vec<Cond>,
    value: usize,
}

/// A memory write: in this state, under these conditions, `mem[addr] <= data`.
struct Write {
    state: u128,
    conds: Vec<Cond>,
    addr: usize,
    data: usize,
}

/// Whether two condition lists can never hold together (one says c, the other not c).
fn exclusive(a: &[Cond], b: &[Cond]) -> bool {
    a.iter().any(|&(c, p)| b.contains(&(c, !p)))
}

#[derive(Default)]
struct Record<'b> {
    /// Signals referred to by index (handles are not `Ord`).
    sigs: Vec<S<'b>>,
    /// Per register (by its signal index), the assignments in program order.
    assigns: BTreeMap<usize, Vec<Assign>>,
    writes: BTreeMap<usize, Vec<Write>>,
    defined: Vec<u128>,
}

impl<'b> Record<'b> {
    fn idx(&mut self, s: S<'b>) -> usize {
        match self.sigs.iter().position(|x| x.sig == s.sig) {
            Some(i) => i,
            None => {
                self.sigs.push(s);
                self.sigs.len() - 1
            }
        }
    }
}

pub struct Fsm<'b, St: States> {
    b: &'b Builder,
    state: S<'b>,
    block: usize,
    rec: RefCell<Record<'b>>,
    is: RefCell<BTreeMap<u128, S<'b>>>,
    /// One constant per state (not shared with other logic), for comparisons and `goto`.
    codes: Vec<S<'b>>,
    init: St,
    _st: std::marker::PhantomData<St>,
}

/// The body of one state: assignments, conditions, transitions.
pub struct StateCtx<'f, 'b, St: States> {
    fsm: &'f Fsm<'b, St>,
    state: u128,
    conds: Vec<Cond>,
}

/// Returned by `when`: the branch taken when the condition is 0.
pub struct Otherwise<'c, 'f, 'b, St: States> {
    ctx: &'c mut StateCtx<'f, 'b, St>,
    cond: usize,
}

impl<'b, St: States> Fsm<'b, St> {
    /// A state machine whose state register `name` powers up and resets to `init`. `doc` is
    /// one line saying what it does.
    pub fn new(b: &'b Builder, name: &str, doc: &str, init: St) -> Fsm<'b, St> {
        let ty = Ty::u(St::width());
        let state = b.reg(name, ty, Some(init.code() as i128));
        let states = St::names().iter().map(|s| s.to_string()).collect();
        // A machine may be built while a pipeline's block is open: that block stays open.
        let block = b.with(|m| {
            let open = m.current_block.take();
            let k = m.begin_block(name, doc, BlockKind::Fsm { state: state.sig.id, states });
            m.current_block = open;
            k
        });
        let codes = St::ALL
            .iter()
            .map(|s| b.s(b.with(|m| m.konst(&format!("{name}_{}", s.name()), ty, s.code() as i128))))
            .collect();
        Fsm {
            b,
            state,
            block,
            rec: RefCell::new(Record::default()),
            is: RefCell::new(BTreeMap::new()),
            codes,
            init,
            _st: Default::default(),
        }
    }

    /// The state register.
    pub fn state_reg(&self) -> S<'b> {
        self.state
    }

    /// 1 while the machine is in `st`: a flip-flop of its own (a one-hot flag beside the
    /// binary state register), loaded with "the next state is `st`" and reset and powered up
    /// with the state, so it equals state = st in every cycle. Conditions and enables then
    /// start from a flip-flop instead of a decode of the state bits: in a large design the
    /// decode put four or five LUTs and their routing between the state register and every
    /// enable (the traversal in the whole core: 8.3 ns, docs/TIMING.md).
    pub fn is(&self, st: St) -> S<'b> {
        if let Some(s) = self.is.borrow().get(&st.code()) {
            return *s;
        }
        let s = self.b.reg(&format!("in_{}", st.name()), Ty::BIT, Some(i128::from(st == self.init)));
        self.is.borrow_mut().insert(st.code(), s);
        s
    }

    /// The whole behaviour of state `st`.
    pub fn state(&self, st: St, body: impl FnOnce(&mut StateCtx<'_, 'b, St>)) {
        {
            let mut rec = self.rec.borrow_mut();
            assert!(!rec.defined.contains(&st.code()), "state {} has two blocks", st.name());
            rec.defined.push(st.code());
        }
        let mut ctx = StateCtx { fsm: self, state: st.code(), conds: Vec::new() };
        body(&mut ctx);
    }

    /// Builds every assigned register's next value and the memory write ports; returns the
    /// next values (for logic that must see a register's next value, such as a memory
    /// addressed one clock ahead). Panics (a bug in the core) when a state has no block.
    pub fn finish(self) -> Nexts<'b> {
        let b = self.b;
        let rec = std::mem::take(&mut *self.rec.borrow_mut());
        for st in St::ALL {
            assert!(
                rec.defined.contains(&st.code()),
                "state {} of {} has no block",
                st.name(),
                b.name_of(self.state.sig)
            );
        }
        let open = b.with(|m| m.current_block.replace(self.block));
        let is = |code: u128| self.is(St::ALL[code as usize]);
        let nots: RefCell<BTreeMap<usize, S<'b>>> = RefCell::new(BTreeMap::new());
        let lit = |(c, p): Cond| -> S<'b> {
            if p {
                return rec.sigs[c];
            }
            *nots.borrow_mut().entry(c).or_insert_with(|| !rec.sigs[c])
        };
        let all = |conds: &[Cond]| -> Option<S<'b>> { conds.iter().map(|&c| lit(c)).reduce(|a, c| a & c) };
        let mut nexts = Nexts(BTreeMap::new());
        let mut targets: Vec<usize> = rec.assigns.keys().copied().collect();
        let state_ix = rec.sigs.iter().position(|s| s.sig == self.state.sig);
        if state_ix.is_none() {
            panic!("{}: a machine that never leaves its first state", b.name_of(self.state.sig));
        }
        targets.sort_unstable();
        for target in targets {
            let list = &rec.assigns[&target];
            let reg = rec.sigs[target];
            let is_state = Some(target) == state_ix;
            // The machine's registers are printed in its process.
            b.with(|m| m.set_block(reg.sig.id, self.block));
            // Per state, the assignments in order: the last one that applies wins.
            let mut arms: Vec<(u128, S<'b>)> = Vec::new();
            for st in St::ALL.iter().map(|s| s.code()) {
                let mine: Vec<&Assign> = list.iter().filter(|a| a.state == st).collect();
                if mine.is_empty() && !is_state {
                    continue;
                }
                let mut v = reg;
                for a in mine {
                    let value = rec.sigs[a.value];
                    v = match all(&a.conds) {
                        None => value,
                        Some(c) => c.select(value, v),
                    };
                }
                arms.push((st, v));
            }
            let next = match arms.as_slice() {
                [(st, v)] if !is_state => is(*st).select(*v, reg),
                // The state register has an arm for every state; a code that is no state (the
                // encoding's spare values) returns to the initial state, so an upset cannot
                // lock the machine.
                _ if is_state => b.case(self.state, &arms, self.codes[self.init.code() as usize]),
                // Set in several states: selected by their flags (one at most is 1), not by a
                // case on the binary state register, whose bits then fed every such register's
                // enable from one place (the whole Cornell core: the state register → two LUTs
                // → `node`'s enable, 7.0 ns, 5.8 of it routing).
                _ => arms.iter().rev().fold(reg, |acc, &(st, v)| is(st).select(v, acc)),
            };
            let next = next.name(&format!("{}_next", b.name_of(reg.sig)));
            b.next(reg, next);
            nexts.0.insert(reg.sig.id.0, next);
        }
        for (&mem, list) in &rec.writes {
            for (i, x) in list.iter().enumerate() {
                for y in &list[i + 1..] {
                    assert!(
                        x.state != y.state || exclusive(&x.conds, &y.conds),
                        "{}: two writes to one memory in state {} that can happen together (a memory has one write port)",
                        b.name_of(self.state.sig),
                        St::ALL[x.state as usize].name()
                    );
                }
            }
            let when: Vec<S<'b>> = list
                .iter()
                .map(|w| match all(&w.conds) {
                    None => is(w.state),
                    Some(c) => is(w.state) & c,
                })
                .collect();
            let we = when.iter().copied().reduce(|a, c| a | c).expect("a write");
            let (mut addr, mut data) = (rec.sigs[list[0].addr], rec.sigs[list[0].data]);
            for (w, c) in list.iter().zip(&when).skip(1) {
                addr = c.select(rec.sigs[w.addr], addr);
                data = c.select(rec.sigs[w.data], data);
            }
            b.ram_write(mem, we, addr, data);
        }
        // The state flags: each loads "the next state is its state".
        let state_next = nexts.of(self.state);
        for (&code, &flag) in self.is.borrow().iter() {
            b.with(|m| m.set_block(flag.sig.id, self.block));
            b.next(flag, state_next.eq(self.codes[code as usize]).name(&format!("{}_next", b.name_of(flag.sig))));
        }
        b.with(|m| m.current_block = open);
        nexts
    }
}

/// The next values of a machine's registers.
pub struct Nexts<'b>(BTreeMap<u32, S<'b>>);

impl<'b> Nexts<'b> {
    pub fn of(&self, reg: S<'b>) -> S<'b> {
        *self.0.get(&reg.sig.id.0).expect("a register the machine assigns")
    }
}

impl<'f, 'b, St: States> StateCtx<'f, 'b, St> {
    /// `reg` gets `value` at the clock edge (unless a later assignment in this state applies).
    pub fn set(&mut self, reg: S<'b>, value: S<'b>) {
        assert_eq!(reg.ty(), value.ty(), "{}: assignment of another type", reg.b.name_of(reg.sig));
        let mut rec = self.fsm.rec.borrow_mut();
        let (target, value) = (rec.idx(reg), rec.idx(value));
        rec.assigns.entry(target).or_default().push(Assign { state: self.state, conds: self.conds.clone(), value });
    }

    /// `reg` gets the constant `v`.
    pub fn set_k(&mut self, reg: S<'b>, v: i128) {
        self.set(reg, reg.k(v));
    }

    /// The next state.
    pub fn goto(&mut self, st: St) {
        self.set(self.fsm.state, self.fsm.codes[st.code() as usize]);
    }

    /// Writes `data` to memory `mem` at `addr` at the clock edge.
    pub fn write(&mut self, mem: usize, addr: S<'b>, data: S<'b>) {
        let mut rec = self.fsm.rec.borrow_mut();
        let (addr, data) = (rec.idx(addr), rec.idx(data));
        let w = Write { state: self.state, conds: self.conds.clone(), addr, data };
        rec.writes.entry(mem).or_default().push(w);
    }

    /// Runs `body` under the condition `cond` (nested conditions combine).
    pub fn when<'c>(&'c mut self, cond: S<'b>, body: impl FnOnce(&mut Self)) -> Otherwise<'c, 'f, 'b, St> {
        assert_eq!(cond.ty(), Ty::BIT, "a condition is one bit");
        let k = self.fsm.rec.borrow_mut().idx(cond);
        self.conds.push((k, true));
        body(self);
        self.conds.pop();
        Otherwise { ctx: self, cond: k }
    }
}

impl<'f, 'b, St: States> Otherwise<'_, 'f, 'b, St> {
    /// Runs `body` when the `when` condition is 0.
    pub fn otherwise(self, body: impl FnOnce(&mut StateCtx<'f, 'b, St>)) {
        self.ctx.conds.push((self.cond, false));
        body(self.ctx);
        self.ctx.conds.pop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::sim::Sim;

    crate::states! {
        enum Light { Red = "red", Green = "green", Yellow = "yellow" }
    }

    /// A counter-driven traffic light: each state's behaviour in one block, the last
    /// assignment winning, unassigned registers holding.
    #[test]
    fn a_machine_steps_through_its_states() {
        let b = Builder::new("light");
        let go = b.input("go", Ty::BIT);
        let count = b.reg("count", Ty::u(4), Some(0));
        let seen = b.reg("seen", Ty::u(4), Some(0));
        let fsm = Fsm::new(&b, "light", "a traffic light", Light::Red);
        fsm.state(Light::Red, |s| {
            s.when(go, |s| {
                s.set_k(count, 0);
                s.goto(Light::Green);
            });
        });
        fsm.state(Light::Green, |s| {
            s.set(count, count + 1);
            s.when(count.eq(2), |s| s.goto(Light::Yellow)).otherwise(|s| s.set(seen, seen + 1));
        });
        fsm.state(Light::Yellow, |s| {
            s.set_k(count, 9);
            s.set_k(count, 7); // the last assignment wins
            s.goto(Light::Red);
        });
        let state = fsm.state_reg();
        fsm.finish();
        b.output("o_state", state);
        b.output("o_count", count);
        b.output("o_seen", seen);
        let m = b.finish();
        let mut sim = Sim::new(&m);
        let out = |name: &str| m.handle(m.outputs.iter().find(|o| o.0 == name).unwrap().1);
        sim.set(m.handle(m.inputs[0]), 1);
        let mut trace = Vec::new();
        for _ in 0..6 {
            sim.tick();
            trace.push((sim.get(out("o_state")), sim.get(out("o_count")), sim.get(out("o_seen"))));
        }
        assert_eq!(trace, [(1, 0, 0), (1, 1, 1), (1, 2, 2), (2, 3, 2), (0, 7, 2), (1, 0, 2)]);
        assert_eq!(Light::width(), 2);
        assert_eq!(Light::Yellow.code(), 2);
    }

    crate::states! {
        enum Three { A = "a", B = "b", C = "c" }
    }

    /// A spare code of the encoding (3 of 2 bits) returns to the initial state; a state
    /// without a `goto` stays.
    #[test]
    fn a_spare_state_code_returns_to_the_initial_state() {
        let b = Builder::new("spare");
        let fsm = Fsm::new(&b, "st", "", Three::B);
        fsm.state(Three::A, |s| s.goto(Three::C));
        fsm.state(Three::B, |s| s.goto(Three::A));
        fsm.state(Three::C, |_| {});
        let state = fsm.state_reg().sig.id;
        fsm.finish();
        b.output("o_state", b.s(b.with(|m| m.handle(state))));
        let m = b.finish();
        let mut sim = Sim::new(&m);
        sim.set(m.handle(state), 3);
        let seen: Vec<i128> = (0..4)
            .map(|_| {
                sim.tick();
                sim.get(m.handle(state))
            })
            .collect();
        assert_eq!(seen, [1, 0, 2, 2]);
    }

    #[test]
    #[should_panic(expected = "one write port")]
    fn two_writes_that_can_happen_together_are_refused() {
        let b = Builder::new("writes");
        let go = b.input("go", Ty::BIT);
        let mem = b.ram("mem", 4, vec![0; 2]);
        let fsm = Fsm::new(&b, "st", "", Three::A);
        fsm.state(Three::A, |s| {
            s.when(go, |s| s.write(mem, go, go.resize(4))).otherwise(|s| s.write(mem, go, go.resize(4)));
            s.write(mem, go, go.resize(4));
            s.goto(Three::B);
        });
        fsm.state(Three::B, |_| {});
        fsm.state(Three::C, |_| {});
        fsm.finish();
    }

    #[test]
    #[should_panic(expected = "state yellow")]
    fn a_state_without_a_block_is_refused() {
        let b = Builder::new("light");
        let fsm = Fsm::new(&b, "light", "", Light::Red);
        fsm.state(Light::Red, |s| s.goto(Light::Green));
        fsm.state(Light::Green, |s| s.goto(Light::Red));
        fsm.finish();
    }
}
