//! The core's result port: a first-word-fall-through queue with credits between the
//! closest-hit unit and `res_*` (DECISIONS 75, docs/CORE.md).

use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// Results a consumer has not taken yet, at most: the result queue's depth. Chosen so that a
/// consumer always ready never holds a ray back (a result holds its place for 7 clocks, from
/// leaving its done queue to leaving the result queue, and at most one leaves per clock).
pub const RESULT_QUEUE: u32 = 16;

/// The result ports behind a queue with credits: a result is taken on a clock with `res_valid`
/// and `res_ready` both 1 and is held until then. A finished ray leaves its done queue only
/// while the result queue has a place it has not promised (`credit_ok`): when the consumer
/// stops, rays finish into the done queues, their slots stay taken, and `ray_ready` falls when
/// the units are full — nothing is lost and nothing waits on a combinational path from
/// `res_ready`. `popped` is the closest-hit unit's `done_valid` (a ray leaving its queue, a
/// clock after the pop).
pub fn result_queue<'b>(
    b: &'b Builder,
    res: &crate::rtl::build::Ports<'b>,
    popped: S<'b>,
    res_ready: S<'b>,
    credit_ok: S<'b>,
) {
    let bit = Ty::BIT;
    let field = |name: &str| res.get(&format!("res_{name}"));
    let words = [b.cat(&[field("id"), field("hit"), field("tri"), field("t")]), b.cat(&[field("u"), field("v")])];
    let take = b.wire("res_take", bit);
    let (heads, nonempty) = super::fifo::fifo_words(b, "res_q", RESULT_QUEUE, field("valid"), &words, take);
    b.drive(take, (nonempty & res_ready).name("res_take_c"));
    // Places not promised, counted with the pops a clock late (`popped`): the queue then holds
    // at most RESULT_QUEUE − credits + popped results, so a pop needs credits − popped ≥ 1,
    // which credits ≥ 2 a clock earlier (registered: `credit_ok`) guarantees.
    let w = RESULT_QUEUE.next_power_of_two().trailing_zeros() + 2;
    let credits = b.reg("res_credits", Ty::u(w), Some(RESULT_QUEUE as i128));
    let credits_next = (credits - popped.resize(w) + take.resize(w)).name("res_credits_next");
    b.next(credits, credits_next);
    b.next(credit_ok, credits_next.slice(1, w - 1).ne(0));
    b.output("res_valid", nonempty);
    // Each word's fields, least significant first (`cat` takes the most significant first).
    let mut out = std::collections::BTreeMap::new();
    for (word, names) in [(0, ["t", "tri", "hit", "id"].as_slice()), (1, ["v", "u"].as_slice())] {
        let mut lsb = 0;
        for name in names {
            let width = field(name).width();
            out.insert(*name, heads[word].slice(lsb, width).name(&format!("res_{name}_q")));
            lsb += width;
        }
    }
    for name in ["id", "hit", "tri", "t", "u", "v"] {
        b.output(&format!("res_{name}"), out[name]);
    }
}
