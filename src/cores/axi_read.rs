//! The core's one AXI4 read master (docs/MEMORY.md "The read port"): the caches ask for whole
//! lines; each asker has a queue of line requests, served round robin, one address per clock
//! at most; every burst is one line (ARLEN = beats − 1, ARSIZE = the data width, ARBURST =
//! INCR), all of one ID, so the memory answers in order; the master keeps the askers of the
//! bursts in flight in a queue and hands each beat to the asker at its head. RREADY is always
//! high: a cache writes a beat the clock it comes. RLAST and RRESP are checked against the
//! master's own beat count (`error`, sticky until reset), never trusted to end a burst.
//!
//! Everything the master drives on the bus is a register; every bus input goes into a register
//! before it reaches logic (the memory may be far away on the die).

use super::fifo::{fifo, fifo_words};
use crate::bits::addr_bits;
use crate::rtl::Ty;
use crate::rtl::build::{Builder, S};

/// The master's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxiReadParams {
    /// Bits of ARADDR.
    pub addr_bits: u32,
    /// Bits of RDATA: 32, 64 or 128.
    pub data_bits: u32,
    /// Beats of a line (one burst).
    pub line_beats: u32,
    /// Bursts in flight, at most.
    pub outstanding: u32,
    /// Line requests an asker may have queued (its queue's depth).
    pub queue: u32,
}

/// An asker's request: a line, as its byte offset from the scene image's base.
pub struct LineRequest<'b> {
    pub valid: S<'b>,
    pub offset: S<'b>,
}

/// The beats of a line, as one asker sees them (two clocks after they crossed the bus: the
/// bus register, then the asker's own, so the burst bookkeeping is not on the path into the
/// caches' fill logic).
#[derive(Clone, Copy)]
pub struct Fill<'b> {
    pub valid: S<'b>,
    /// What `valid` will be next clock (the bus side's logic before the asker's register): a
    /// cache computes its record RAMs' write enables from it a clock early, into registers.
    pub valid_next: S<'b>,
    pub data: S<'b>,
    /// The beat's number in its line.
    pub beat: S<'b>,
    pub last: S<'b>,
}

/// The bus inputs.
pub struct AxiIn<'b> {
    pub arready: S<'b>,
    pub rvalid: S<'b>,
    pub rdata: S<'b>,
    pub rlast: S<'b>,
    pub rresp: S<'b>,
}

/// The bus outputs (ARBURST, ARSIZE and RREADY are constants: `AxiReadParams::arsize`).
pub struct AxiOut<'b> {
    pub arvalid: S<'b>,
    pub araddr: S<'b>,
    pub arlen: S<'b>,
    pub error: S<'b>,
}

impl AxiReadParams {
    /// ARSIZE: log2 of the bytes of a beat.
    pub fn arsize(&self) -> u32 {
        (self.data_bits / 8).trailing_zeros()
    }
}

/// The master for `requests.len()` askers, reading the image at `base` (a byte address).
pub fn axi_read<'b>(
    b: &'b Builder,
    p: &AxiReadParams,
    base: S<'b>,
    requests: &[LineRequest<'b>],
    bus: &AxiIn<'b>,
) -> (AxiOut<'b>, Vec<Fill<'b>>) {
    let n = requests.len() as u32;
    let id_bits = addr_bits(n as usize);
    let ab = p.addr_bits;
    b.stage("axi_ar", "line requests queued per cache; one address a clock, round robin; bursts in flight counted");
    let queues: Vec<(S<'b>, S<'b>, S<'b>)> = requests
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let pop = b.wire(&format!("axi_q{k}_pop"), Ty::BIT);
            let f = fifo(b, &format!("axi_q{k}"), ab, p.queue, r.valid, r.offset.resize(ab), pop);
            (f.nonempty, f.head, pop)
        })
        .collect();
    // The address register: loaded when empty or taken this clock, while fewer than
    // `outstanding` bursts are in flight (a burst counts from its load to its last beat).
    let arvalid = b.reg("axi_arvalid", Ty::BIT, Some(0));
    let araddr = b.reg("axi_araddr", Ty::u(ab), None);
    let taken = (arvalid & bus.arready).name("axi_ar_taken");
    let fb = addr_bits(p.outstanding as usize + 1) + 1;
    let in_flight = b.reg("axi_in_flight", Ty::u(fb), Some(0));
    let room = in_flight.lt(p.outstanding as i128).name("axi_room");
    let free = (((!arvalid) | taken) & room).name("axi_free");
    // Round robin: of the askers after the last one served (wrapping), the first with a request.
    let last = b.reg("axi_last", Ty::u(id_bits), Some(0));
    let mut pick = b.konst(Ty::u(id_bits), 0);
    let mut any = b.konst(Ty::BIT, 0);
    for step in (1..=n).rev() {
        let cand = (0..n).fold(b.konst(Ty::u(id_bits), 0), |acc, k| {
            let c = (k + step) % n;
            last.eq(k as i128).select(b.konst(Ty::u(id_bits), c as i128), acc)
        });
        let has = (0..n).fold(b.konst(Ty::BIT, 0), |acc, k| acc | (cand.eq(k as i128) & queues[k as usize].0));
        pick = has.select(cand, pick);
        any = any | has;
    }
    let pick = pick.name("axi_pick");
    let go = (free & any).name("axi_go");
    for (k, q) in queues.iter().enumerate() {
        b.drive(q.2, go & pick.eq(k as i128));
    }
    b.next_when(last, go, pick);
    let one = b.konst(Ty::BIT, 1);
    b.next(arvalid, go.select(one, taken.select(one.k(0), arvalid)));
    let head = queues.iter().enumerate().fold(b.konst(Ty::u(ab), 0), |acc, (k, q)| pick.eq(k as i128).select(q.1, acc));
    b.next_when(araddr, go, (head + base.resize(ab)).name("axi_next_addr"));
    b.end_stage();

    b.stage("axi_r", "each beat registered, handed to the asker of the oldest burst; bursts counted off");
    // The askers of the bursts in flight, oldest first (pushed at load, so never more than
    // `outstanding`).
    let (rvalid, rdata) = (b.delay("axi_rvalid_r", bus.rvalid), b.delay("axi_rdata_r", bus.rdata));
    let (rlast, rresp) = (b.delay("axi_rlast_r", bus.rlast), b.delay("axi_rresp_r", bus.rresp));
    let beat_bits = addr_bits(p.line_beats as usize);
    let beat = b.reg("axi_beat", Ty::u(beat_bits), Some(0));
    let last_beat = beat.eq((p.line_beats - 1) as i128).name("axi_last_beat");
    let done = b.wire("axi_burst_done", Ty::BIT);
    let who_pop = b.wire("axi_who_pop", Ty::BIT);
    let (who, who_nonempty) = fifo_words(b, "axi_who", p.outstanding, go, &[pick], who_pop, false);
    b.drive(done, rvalid & who_nonempty & last_beat);
    b.drive(who_pop, done);
    let who = who[0];
    let counted = (rvalid & who_nonempty).name("axi_counted");
    b.next_when(beat, counted, last_beat.select(beat.k(0), beat + 1));
    let change = go.resize(fb) - done.resize(fb);
    b.next(in_flight, in_flight + change);
    // A beat with no burst in flight, RLAST where the count does not end the burst (or none
    // where it does), or an RRESP other than OKAY: the memory broke the protocol.
    let bad = (rvalid & ((!who_nonempty) | rlast.ne(last_beat) | rresp.ne(0))).name("axi_bad_beat");
    let error = b.reg("axi_error", Ty::BIT, Some(0));
    b.next(error, error | bad);
    b.end_stage();
    let (data, fill_beat, fill_last) =
        (b.delay("axi_fill_data", rdata), b.delay("axi_fill_beat", beat), b.delay("axi_fill_last", last_beat));
    let fills = (0..n)
        .map(|k| {
            let valid_next = (rvalid & who_nonempty & who.eq(k as i128)).name(&format!("axi_fill{k}_c"));
            Fill {
                valid: b.valid_delay(&format!("axi_fill{k}"), valid_next),
                valid_next,
                data,
                beat: fill_beat,
                last: fill_last,
            }
        })
        .collect();
    let arlen = b.konst(Ty::u(8), (p.line_beats - 1) as i128);
    (AxiOut { arvalid, araddr, arlen, error }, fills)
}
