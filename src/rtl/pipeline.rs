//! The pipeline-stage construct. A pipeline knows at which stage every signal is produced:
//! logic built between two `stage` calls belongs to the stage in between, and the registers a
//! `stage` call creates to the next one. `now(x)` returns x as seen in the current stage,
//! delayed by a shift register when it was produced earlier, so tags and operands that ride
//! along (valid bits, triangle fields) are never carried by hand and never miscounted. Each
//! stage registers a **bundle**: a struct of named signals (`bundle!`), so fields are read by
//! name, not position. The latency is the count of registered stages plus the latency of
//! instances (`instance`).
//!
//! A stage can be left unregistered by name (`Policy::merge`): its logic then runs in the same
//! clock as the next stage's, every later signal is aligned automatically and the latency drops
//! by one, without touching the core's description — the hook for pipelining to a clock target.

use super::build::{Builder, Ports, S};
use super::netlist::BlockKind;
use super::netlist::Module;
use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::rc::Rc;

/// A struct of signals that a stage can register field by field.
pub trait Bundle<'b>: Sized {
    /// The same bundle with every field passed through `f(field name, signal)`.
    fn map_fields(self, f: &mut dyn FnMut(&'static str, S<'b>) -> S<'b>) -> Self;
}

/// Declares a bundle: `bundle! { pub struct Products { onp, onq } }` (fields are signals).
#[macro_export]
macro_rules! bundle {
    ($(#[$meta:meta])* $vis:vis struct $name:ident { $($field:ident),+ $(,)? }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug)]
        $vis struct $name<'b> { $(pub $field: $crate::rtl::build::S<'b>),+ }
        impl<'b> $crate::rtl::pipeline::Bundle<'b> for $name<'b> {
            fn map_fields(
                self,
                f: &mut dyn FnMut(&'static str, $crate::rtl::build::S<'b>) -> $crate::rtl::build::S<'b>,
            ) -> Self {
                $name { $($field: f(stringify!($field), self.$field)),+ }
            }
        }
    };
}

/// Which stages get their registers.
#[derive(Clone, Debug, Default)]
pub struct Policy {
    /// Stages (by name) left unregistered: merged into the next one.
    pub merge: Vec<String>,
}

pub struct Pipeline<'b> {
    b: &'b Builder,
    policy: Policy,
    /// The first signal id of each stage after the first: a signal with id < bounds[0] is
    /// produced in stage 0, etc. Equal bounds are instances' latency (`instance`).
    bounds: RefCell<Vec<u32>>,
    /// Delayed copies already made: (signal, delay) → copy.
    delayed: RefCell<BTreeMap<(u32, u32), S<'b>>>,
    /// Stages passed (registered, or inside an instance): the current stage number.
    stage: Cell<u32>,
    /// Every stage name seen, to check the policy's names against.
    names: RefCell<Vec<String>>,
    /// Valid bits (`valid`) and their copies: their registers are cleared by `rst`, so a
    /// reset leaves nothing in flight.
    valids: RefCell<std::collections::BTreeSet<u32>>,
}

impl<'b> Pipeline<'b> {
    /// A pipeline starting at stage 0 with the signals that exist now (its inputs).
    pub fn new(b: &'b Builder, policy: Policy) -> Pipeline<'b> {
        // The open block holds the logic feeding the next stage's registers; `stage` names it.
        b.with(|m| m.begin_block("s1", "", BlockKind::Stage));
        Pipeline {
            b,
            policy,
            bounds: RefCell::new(Vec::new()),
            delayed: RefCell::new(BTreeMap::new()),
            stage: Cell::new(0),
            names: RefCell::new(Vec::new()),
            valids: RefCell::new(Default::default()),
        }
    }

    /// Marks `x` as a valid bit: every register that carries it down the pipeline is one that
    /// `rst` clears.
    pub fn valid(&self, x: S<'b>) -> S<'b> {
        self.valids.borrow_mut().insert(x.sig.id.0);
        x
    }

    fn is_valid(&self, x: S<'b>) -> bool {
        self.valids.borrow().contains(&x.sig.id.0)
    }

    /// `x` `d` clocks later: a valid line for a valid bit, else a shift register.
    fn delayed_copy(&self, name: &str, x: S<'b>, d: u32) -> S<'b> {
        if self.is_valid(x) { self.valid(self.b.valid_line(name, x, d)) } else { self.b.delay_line(name, x, d) }
    }

    /// The stage a signal is produced in.
    pub fn born(&self, s: S<'b>) -> u32 {
        self.bounds.borrow().partition_point(|&b| b <= s.sig.id.0) as u32
    }

    fn next_id(&self) -> u32 {
        self.b.with(|m| m.signals.len() as u32)
    }

    /// `x` as seen in the current stage: delayed by the stages since it was produced.
    pub fn now(&self, x: S<'b>) -> S<'b> {
        // A constant is the same in every stage.
        if self.b.with(|m| matches!(m.sig(x.sig.id).def, super::netlist::Def::Const(_))) {
            return x;
        }
        let d = self.stage.get() - self.born(x);
        if d == 0 {
            return x;
        }
        let key = (x.sig.id.0, d);
        if let Some(s) = self.delayed.borrow().get(&key) {
            return *s;
        }
        // Extend the longest copy made so far, so a signal read at many stages costs one
        // register per stage, not one line per reader.
        let (base, from) = self
            .delayed
            .borrow()
            .range((x.sig.id.0, 0)..(x.sig.id.0, d))
            .next_back()
            .map_or((x, 0), |(k, s)| (*s, k.1));
        let name = format!("{}_d{d}", self.b.name_of(x.sig));
        let s = self.delayed_copy(&name, base, d - from);
        self.delayed.borrow_mut().insert(key, s);
        s
    }

    /// Ends the current stage: every field of `bundle`, aligned to this stage, gets a
    /// register (named `s{k}_{field}`) unless the policy merges the stage named `name`. Returns
    /// the bundle as seen in the next stage.
    pub fn stage<B: Bundle<'b>>(&self, name: &str, doc: &str, bundle: B) -> B {
        self.names.borrow_mut().push(name.to_string());
        let aligned = bundle.map_fields(&mut |field, s| {
            let s = self.now(s);
            // A field's logic with only a numbered name takes the field's name.
            if self.b.is_numbered(s.sig) { s.name(field) } else { s }
        });
        if self.policy.merge.iter().any(|m| m == name) {
            return aligned;
        }
        let k = self.stage.get() + 1;
        self.b.with(|m| {
            let block = m.current_block.expect("a pipeline's block is open");
            m.blocks[block].name = crate::rtl::names::legal(&format!("s{k}_{name}"));
            m.blocks[block].doc = doc.to_string();
        });
        // The registers are the first signals of stage k (and printed in this block).
        self.bounds.borrow_mut().push(self.next_id());
        self.stage.set(k);
        let registered = aligned.map_fields(&mut |field, s| self.delayed_copy(&format!("s{k}_{field}"), s, 1));
        self.b.with(|m| {
            m.end_block();
            m.begin_block(&format!("s{}", k + 1), "", BlockKind::Stage);
        });
        registered
    }

    /// Instantiates `sub`, a pipeline of its own `cycles` registers deep: its inputs are
    /// aligned to the current stage, and its outputs belong to the stage `cycles` later.
    pub fn instance(&self, label: &str, sub: &Rc<Module>, inputs: &[S<'b>], cycles: u32) -> Ports<'b> {
        let aligned: Vec<S<'b>> = inputs.iter().map(|&s| self.now(s)).collect();
        let id = self.next_id();
        for _ in 0..cycles {
            self.bounds.borrow_mut().push(id);
        }
        self.stage.set(self.stage.get() + cycles);
        self.b.instance(label, sub, &aligned)
    }

    /// Clock cycles from the inputs to the current stage.
    pub fn latency(&self) -> u32 {
        self.stage.get()
    }

    /// Closes the last block (the logic after the last stage's registers). Panics (a bug in
    /// the core) when the policy names a stage that does not exist.
    pub fn finish(self) -> u32 {
        for m in &self.policy.merge {
            assert!(self.names.borrow().contains(m), "the pipeline has no stage {m} to merge");
        }
        self.b.with(|m| {
            let block = m.current_block.expect("a pipeline's block is open");
            m.blocks[block].name = crate::rtl::names::legal(&format!("s{}_out", self.stage.get()));
            m.blocks[block].doc = "after the last stage".into();
            m.end_block();
        });
        self.stage.get()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rtl::Ty;
    use crate::rtl::sim::Sim;

    crate::bundle! { struct Sum { s, carry } }

    /// (a + b) · c over two stages, with c aligned automatically, with and without merging
    /// the first stage: the same values, one cycle less latency.
    #[test]
    fn stages_align_late_operands_and_merge_by_policy() {
        for merge in [false, true] {
            let b = Builder::new("p");
            let (x, y, c) = (b.input("x", Ty::u(8)), b.input("y", Ty::u(8)), b.input("c", Ty::u(8)));
            let policy = Policy { merge: if merge { vec!["sum".into()] } else { vec![] } };
            let p = Pipeline::new(&b, policy);
            let sum = p.stage("sum", "a + b", Sum { s: x + y, carry: (x.resize(9) + y.resize(9)).bit(8) });
            let prod = sum.s.xmul(p.now(c));
            let out = p.stage("out", "product", Sum { s: prod, carry: sum.carry });
            let lat = p.finish();
            b.output("o", out.s);
            let m = b.finish();
            assert_eq!(lat, if merge { 1 } else { 2 });
            let mut sim = Sim::new(&m);
            let ins: Vec<_> = m.inputs.iter().map(|&i| m.handle(i)).collect();
            let o = m.handle(m.outputs[0].1);
            let mut got = Vec::new();
            for t in 0..10i128 {
                sim.set(ins[0], t);
                sim.set(ins[1], 2 * t);
                sim.set(ins[2], t + 1);
                sim.tick();
                got.push(sim.get(o));
            }
            let want = |t: i128| ((3 * t) % 256) * (t + 1);
            let start = lat as i128 - 1;
            for t in start..10 {
                assert_eq!(got[t as usize], want(t - start), "merge {merge} cycle {t}");
            }
        }
    }
}
