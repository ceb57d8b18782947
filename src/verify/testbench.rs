//! Self-checking testbenches: the Rust simulator produces the expected outputs for a list of
//! input vectors, and the askama templates in `testbenches/` turn them into a VHDL and a
//! Verilog testbench that apply the same inputs to the generated HDL and compare. Each kind of
//! testbench is one struct for both languages: its template includes the language's file.

use super::simulators::{Simulator, tb_name};
use crate::cores::top_memory::is_memory_port;
use crate::rtl::netlist::{Module, SigId};
use crate::rtl::sim::Sim;
use crate::rtl::width::Ty;
use askama::Template;

pub struct Port {
    pub name: String,
    pub ty: Ty,
    pub width: u32,
    /// VHDL type, e.g. `signed(31 downto 0)`.
    pub vtype: String,
    /// VHDL conversion function from std_logic_vector: `signed` or `unsigned`.
    pub kind: &'static str,
    /// Verilog declaration, e.g. `signed [31:0]`.
    pub decl: String,
    /// Position in the Verilog vector word.
    pub msb: u32,
    pub lsb: u32,
}

/// The vector testbench: `vector_tb.vhd` (GHDL) or `vector_tb.v` (Icarus). The vectors are
/// one word per clock, most significant first: [rst] inputs… outputs… (`total_width` bits).
#[derive(Template)]
#[template(path = "vector_tb.tpl", escape = "none")]
struct VectorTb<'a> {
    vhdl: bool,
    tb: &'a str,
    module: &'a str,
    vectors: &'a str,
    has_reset: bool,
    reset_bit: u32,
    inputs: &'a [Port],
    outputs: &'a [Port],
    total_width: u32,
    count: usize,
}

/// A port as the C++ harness sees it: its 32-bit words at `offset` in a clock's line.
pub struct CppPort {
    pub name: String,
    pub words: u32,
    pub offset: u32,
}

#[derive(Template)]
#[template(path = "verilator_harness.cpp", escape = "none")]
struct VerilatorHarness<'a> {
    module: &'a str,
    vectors: &'a str,
    has_reset: bool,
    stride: u32,
    inputs: &'a [CppPort],
    outputs: &'a [CppPort],
}

/// The stream testbench: `stream_tb.vhd` (GHDL) or `stream_tb.v` (Icarus, Verilator).
#[derive(Template)]
#[template(path = "stream_tb.tpl", escape = "none")]
struct StreamTb<'a> {
    vhdl: bool,
    tb: &'a str,
    module: &'a str,
    rays: &'a str,
    expected: &'a str,
    results: &'a str,
    stalls: &'a str,
    has_reset: bool,
    inputs: &'a [Port],
    outputs: &'a [Port],
    checked: &'a [Port],
    /// The checked output whose value is the result's id.
    id: &'a str,
    ray_width: u32,
    /// Bits of the checked outputs; an expected word has one more, on top: "a ray has this id".
    result_width: u32,
    count: usize,
    /// Expected words: ids 0 … ids − 1.
    ids: usize,
    /// Entries of the stall pattern; 0: the source never stalls (no stall file).
    stall_period: usize,
    /// The core has a `res_ready` input; the consumer's pattern file, and its entries (0:
    /// always ready, no file).
    has_res_ready: bool,
    sink: &'a str,
    sink_period: usize,
    /// Cycles with `rst` high for one clock.
    resets: &'a [u64],
    max_cycles: u64,
    /// An external-memory core's memory inputs (driven by the memory model `mem_model`), and
    /// the image's base address as a Verilog literal and as VHDL bits.
    mem_inputs: &'a [Port],
    mem_model: &'a str,
    mem_base: String,
    mem_base_bits: String,
}

/// A stream testbench's data: the inputs of each ray (every input port but `ray_valid`, in
/// port order) in the order the source offers them, and, indexed by id, the expected values of
/// the `checked` outputs of the result with that id (the value of output `id`, one of them);
/// None for an id no ray has. Results may come in any order.
pub struct Stream<'a> {
    pub rays: &'a [Vec<i128>],
    pub expected: &'a [Option<Vec<i128>>],
    pub checked: &'a [&'a str],
    pub id: &'a str,
    /// The source's stall pattern: it holds `ray_valid` low on cycle c if entry c mod len is
    /// true (`verify::feed::Stalls`); None: never.
    pub stalls: Option<&'a [bool]>,
    /// The consumer's pattern: it holds `res_ready` low on cycle c if entry c mod len is true;
    /// None: always ready.
    pub sink: Option<&'a [bool]>,
    /// Cycles with `rst` high for one clock (ascending): nothing is transferred in that clock,
    /// and the testbench starts the frame again after it (results before it are checked for
    /// being right, not for being complete; `results.txt` holds those after the last reset).
    pub resets: &'a [u64],
    pub max_cycles: u64,
    /// With an external-memory core: the image's base address (`mem_base`; the memory model's
    /// files are the caller's, `verify::memory_hdl::model_files`).
    pub mem_base: Option<u64>,
}

/// The stream testbench for GHDL (VHDL) or Icarus/Verilator (Verilog), with its data files
/// and the design. `rays.txt`: a ray per line in feed order; `expected.txt`: a line per id
/// 0 … max: a 1 bit ("a ray has this id") then the expected checked outputs (zeros and a 0 bit
/// for an id no ray has); `stalls.txt` (with stalls): a 0 or 1 per line, the pattern. Lines are
/// binary strings, a field each, for VHDL, one hex word for Verilog (`$readmemh`; the stall
/// bits are read with `$readmemb`). The testbench looks each result up by its id (a result
/// for an unknown id, a second result for an id and an id without result each fail) and
/// writes `results.txt`, one line of checked outputs per result, in arrival order.
pub fn stream_files(m: &Module, s: &Stream, sim: Simulator) -> Vec<(String, String)> {
    let in_ids: Vec<(String, SigId)> =
        input_ids(m).into_iter().filter(|(n, _)| n != "ray_valid" && n != "res_ready" && !is_memory_port(n)).collect();
    let mem_ids: Vec<(String, SigId)> = input_ids(m).into_iter().filter(|(n, _)| is_memory_port(n)).collect();
    let (mem_inputs, _) = ports(m, &mem_ids, 0);
    assert_eq!(mem_inputs.is_empty(), s.mem_base.is_none(), "a memory model for an external-memory core alone");
    let base = s.mem_base.unwrap_or(0);
    let base_width = mem_inputs.iter().find(|p| p.name == "mem_base").map_or(1, |p| p.width);
    let has_res_ready = input_ids(m).iter().any(|(n, _)| n == "res_ready");
    let checked_ids: Vec<(String, SigId)> =
        s.checked.iter().map(|c| m.outputs.iter().find(|o| o.0 == *c).expect("checked output").clone()).collect();
    let (inputs, ray_width) = ports(m, &in_ids, 0);
    let (checked, result_width) = ports(m, &checked_ids, 0);
    let id = checked.iter().find(|p| p.name == s.id).expect("the id output is checked");
    assert!(!id.ty.signed, "the id output is unsigned");
    let (outputs, _) = ports(m, &m.outputs, 0);
    let (rays, expected, results, stalls, sink) =
        ("rays.txt", "expected.txt", "results.txt", "stalls.txt", "ready.txt");
    let vhdl = sim == Simulator::Ghdl;
    let mut files = crate::rtl::emit::design_files(m, ext(vhdl));
    let fields = |row: &[i128], ports: &[Port]| -> Vec<(u128, u32)> {
        ports.iter().zip(row).map(|(p, v)| (p.ty.wrap(*v), p.width)).collect()
    };
    let ray_lines: String = s.rays.iter().map(|row| data_line(&fields(row, &inputs), vhdl, ray_width)).collect();
    files.push((rays.into(), ray_lines));
    let none = vec![0; checked.len()];
    let expected_lines: String = s
        .expected
        .iter()
        .map(|row| {
            let known = (row.is_some() as u128, 1);
            let line: Vec<(u128, u32)> =
                std::iter::once(known).chain(fields(row.as_deref().unwrap_or(&none), &checked)).collect();
            data_line(&line, vhdl, result_width + 1)
        })
        .collect();
    files.push((expected.into(), expected_lines));
    let bits_file = |bits: &[bool]| bits.iter().map(|&b| if b { "1\n" } else { "0\n" }).collect::<String>();
    if let Some(bits) = s.stalls {
        files.push((stalls.into(), bits_file(bits)));
    }
    assert!(
        has_res_ready || (s.sink.is_none() && s.resets.is_empty()),
        "a consumer pattern or resets need res_ready and rst"
    );
    if let Some(bits) = s.sink {
        files.push((sink.into(), bits_file(bits)));
    }
    let text = StreamTb {
        vhdl,
        tb: &tb_name(m),
        module: &tb_entity(m, vhdl),
        rays,
        expected,
        results,
        stalls,
        has_reset: m.has_reset(),
        inputs: &inputs,
        outputs: &outputs,
        checked: &checked,
        id: s.id,
        ray_width,
        result_width,
        count: s.rays.len(),
        ids: s.expected.len(),
        stall_period: s.stalls.map_or(0, |b| b.len()),
        has_res_ready,
        sink,
        sink_period: s.sink.map_or(0, |b| b.len()),
        resets: s.resets,
        max_cycles: s.max_cycles,
        mem_inputs: &mem_inputs,
        mem_model: super::memory_hdl::MODEL,
        mem_base: format!("{base_width}'h{base:x}"),
        mem_base_bits: (0..base_width)
            .rev()
            .map(|k| if (base >> k.min(63)) & 1 == 1 && k < 64 { '1' } else { '0' })
            .collect(),
    }
    .render();
    files.push((format!("tb.{}", ext(vhdl)), text.expect("testbench template renders") + "\n"));
    files
}

/// The entity or module a testbench instantiates: in VHDL the numeric_std one
/// (`emit::vhdl::entity`), whose ports the testbenches' signals have.
fn tb_entity(m: &Module, vhdl: bool) -> String {
    if vhdl { crate::rtl::emit::vhdl::entity(m) } else { m.name.clone() }
}

/// The file extension of a language.
fn ext(vhdl: bool) -> &'static str {
    if vhdl { "vhd" } else { "v" }
}

/// One line of a data file, fields (value, width) most significant first: binary strings
/// separated by spaces for VHDL (read with textio), one hex word of `width` bits for Verilog
/// (`$readmemh`); with the newline.
fn data_line(fields: &[(u128, u32)], vhdl: bool, width: u32) -> String {
    let mut line = if vhdl {
        fields.iter().map(|&(v, w)| crate::rtl::emit::bit_string(v, w)).collect::<Vec<_>>().join(" ")
    } else {
        let mut word = num_word::Word::default();
        fields.iter().for_each(|&(v, w)| word.push(v, w));
        word.hex(width)
    };
    line.push('\n');
    line
}

/// Parses a stream testbench's `results.txt`: each line's binary fields as values of the
/// checked outputs' types.
pub fn parse_results(m: &Module, checked: &[&str], text: &str) -> Result<Vec<Vec<i128>>, String> {
    let tys: Vec<Ty> = checked
        .iter()
        .map(|c| m.outputs.iter().find(|o| o.0 == *c).map(|o| m.sig(o.1).ty).ok_or(format!("no output {c}")))
        .collect::<Result<_, _>>()?;
    text.lines()
        .enumerate()
        .map(|(i, line)| {
            let fields: Vec<&str> = line.split_whitespace().collect();
            if fields.len() != tys.len() {
                return Err(format!("results line {}: {} fields, expected {}", i + 1, fields.len(), tys.len()));
            }
            fields
                .iter()
                .zip(&tys)
                .map(|(f, ty)| {
                    u128::from_str_radix(f, 2)
                        .map(|bits| ty.value(bits))
                        .map_err(|_| format!("results line {}: '{f}' is not binary", i + 1))
                })
                .collect()
        })
        .collect()
}

/// One clock's stimulus: the reset input and every data input, in `Module::inputs` order.
#[derive(Clone, Debug)]
pub struct Stimulus {
    pub reset: bool,
    pub inputs: Vec<i128>,
}

/// Inputs and the expected outputs (bit patterns) of each clock.
pub struct Transcript {
    pub stimuli: Vec<Stimulus>,
    pub outputs: Vec<Vec<u128>>,
}

/// Runs the Rust simulator over the stimuli, recording every output after each clock edge.
pub fn record(m: &Module, stimuli: Vec<Stimulus>) -> Transcript {
    let mut sim = Sim::new(m);
    let ins: Vec<_> = m.inputs.iter().map(|&i| m.handle(i)).collect();
    let outs: Vec<_> = m.outputs.iter().map(|(_, i)| m.handle(*i)).collect();
    let mut outputs = Vec::with_capacity(stimuli.len());
    for st in &stimuli {
        sim.reset = st.reset;
        for (s, v) in ins.iter().zip(&st.inputs) {
            sim.set(*s, *v);
        }
        sim.tick();
        outputs.push(outs.iter().map(|o| o.ty.wrap(sim.get(*o))).collect());
    }
    Transcript { stimuli, outputs }
}

fn ports(m: &Module, ids: &[(String, SigId)], mut lsb: u32) -> (Vec<Port>, u32) {
    let mut v = Vec::new();
    for (name, id) in ids.iter().rev() {
        let t = m.sig(*id).ty;
        v.push(Port {
            name: name.clone(),
            ty: t,
            width: t.width,
            vtype: format!("{}({} downto 0)", if t.signed { "signed" } else { "unsigned" }, t.width - 1),
            kind: if t.signed { "signed" } else { "unsigned" },
            decl: format!("{}[{}:0]", if t.signed { "signed " } else { "" }, t.width - 1),
            msb: lsb + t.width - 1,
            lsb,
        });
        lsb += t.width;
    }
    v.reverse();
    (v, lsb)
}

/// Replays `t` in simulator `sim` in a fresh folder `dir` (kept for inspection): the design,
/// its vector testbench and the `extra` files (a model the testbench needs, or a design file
/// that replaces the printed one). The testbench's (passed, failed) clocks.
pub fn replay(
    m: &Module,
    t: &Transcript,
    sim: Simulator,
    dir: &std::path::Path,
    extra: &[(String, String)],
) -> Result<(u64, u64), String> {
    let _ = std::fs::remove_dir_all(dir);
    let write =
        |file: &str, text: &str| std::fs::write(dir.join(file), text).map_err(|e| format!("{}: {e}", dir.display()));
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    for (file, text) in bench_files(m, t, sim).iter().chain(extra) {
        write(file, text)?;
    }
    sim.run(dir, m)
}

/// Everything one simulator needs in its directory: the design in its language (one file per
/// module), its testbench and its vectors, as (file name, contents).
pub fn bench_files(m: &Module, t: &Transcript, sim: Simulator) -> Vec<(String, String)> {
    let mut files = crate::rtl::emit::design_files(m, ext(sim == Simulator::Ghdl));
    files.extend(match sim {
        Simulator::Ghdl => render_vectors(m, t, true),
        Simulator::Iverilog | Simulator::IverilogSv => render_vectors(m, t, false),
        Simulator::Verilator => render_harness(m, t),
    });
    files
}

/// Input ports in `Module::inputs` order.
fn input_ids(m: &Module) -> Vec<(String, SigId)> {
    m.inputs.iter().map(|&i| (m.sig(i).name.clone(), i)).collect()
}

/// The vector testbench in VHDL with `vectors.txt` (a line of bit strings per clock), or in
/// Verilog with `vectors.hex` (a `$readmemh` word per clock).
fn render_vectors(m: &Module, t: &Transcript, vhdl: bool) -> Vec<(String, String)> {
    let (outputs, after_out) = ports(m, &m.outputs, 0);
    let (inputs, after_in) = ports(m, &input_ids(m), after_out);
    let has_reset = m.has_reset();
    let total_width = after_in + has_reset as u32;
    let mut data = String::new();
    for (st, out) in t.stimuli.iter().zip(&t.outputs) {
        let reset = has_reset.then_some((st.reset as u128, 1));
        let ins = inputs.iter().zip(&st.inputs).map(|(p, v)| (p.ty.wrap(*v), p.width));
        let outs = outputs.iter().zip(out).map(|(p, v)| (*v, p.width));
        let fields: Vec<(u128, u32)> = reset.into_iter().chain(ins).chain(outs).collect();
        data.push_str(&data_line(&fields, vhdl, total_width));
    }
    let vectors = if vhdl { "vectors.txt" } else { "vectors.hex" };
    let text = VectorTb {
        vhdl,
        tb: &tb_name(m),
        module: &tb_entity(m, vhdl),
        vectors,
        has_reset,
        reset_bit: total_width - 1,
        inputs: &inputs,
        outputs: &outputs,
        total_width,
        count: t.stimuli.len(),
    }
    .render()
    .expect("testbench template renders");
    vec![(format!("tb.{}", ext(vhdl)), text + "\n"), (vectors.into(), data)]
}

/// The Verilator harness: ports as 32-bit words, one line of words per clock.
fn render_harness(m: &Module, t: &Transcript) -> Vec<(String, String)> {
    let has_reset = m.has_reset();
    let mut offset = has_reset as u32;
    let mut layout = |ids: Vec<(String, Ty)>| -> Vec<CppPort> {
        ids.into_iter()
            .map(|(name, ty)| {
                let p = CppPort { name, words: ty.width.div_ceil(32), offset };
                offset += p.words;
                p
            })
            .collect()
    };
    let inputs = layout(m.inputs.iter().map(|&i| (m.sig(i).name.clone(), m.sig(i).ty)).collect());
    let outputs = layout(m.outputs.iter().map(|(n, i)| (n.clone(), m.sig(*i).ty)).collect());
    let stride = offset;
    let in_tys: Vec<Ty> = m.inputs.iter().map(|&i| m.sig(i).ty).collect();
    let out_tys: Vec<Ty> = m.outputs.iter().map(|(_, i)| m.sig(*i).ty).collect();
    let mut text = String::new();
    let push = |v: u128, w: u32, line: &mut Vec<String>| {
        for k in 0..w.div_ceil(32) {
            line.push(format!("{:x}", (v >> (32 * k)) as u32));
        }
    };
    for (st, out) in t.stimuli.iter().zip(&t.outputs) {
        let mut line = Vec::with_capacity(stride as usize);
        if has_reset {
            line.push(if st.reset { "1".into() } else { "0".into() });
        }
        for (ty, v) in in_tys.iter().zip(&st.inputs) {
            push(ty.wrap(*v), ty.width, &mut line);
        }
        for (ty, v) in out_tys.iter().zip(out) {
            push(*v, ty.width, &mut line);
        }
        text.push_str(&line.join(" "));
        text.push('\n');
    }
    let cpp = VerilatorHarness {
        module: &m.name,
        vectors: "vectors.words",
        has_reset,
        stride,
        inputs: &inputs,
        outputs: &outputs,
    }
    .render()
    .expect("harness template renders");
    vec![("harness.cpp".into(), cpp + "\n"), ("vectors.words".into(), text)]
}

/// A wide word built field by field, most significant first.
mod num_word {
    #[derive(Default)]
    pub struct Word {
        bits: Vec<bool>,
    }
    impl Word {
        pub fn push(&mut self, v: u128, w: u32) {
            for b in (0..w).rev() {
                self.bits.push((v >> b) & 1 == 1);
            }
        }
        pub fn hex(&self, width: u32) -> String {
            let digits = width.div_ceil(4) as usize;
            let pad = digits * 4 - self.bits.len();
            let all: Vec<bool> = std::iter::repeat_n(false, pad).chain(self.bits.iter().copied()).collect();
            all.chunks(4)
                .map(|c| char::from_digit(c.iter().fold(0, |a, &b| a * 2 + b as u32), 16).unwrap_or('0'))
                .collect()
        }
    }
}
