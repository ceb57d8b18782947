//! Self-checking testbenches: the Rust simulator produces the expected outputs for a list of
//! input vectors, and the askama templates in `testbenches/` turn them into a VHDL and a
//! Verilog testbench that apply the same inputs to the generated HDL and compare.

use crate::rtl::netlist::{Module, SigId};
use crate::rtl::sim::Sim;
use crate::rtl::width::Ty;
use askama::Template;

pub struct Port {
    pub name: String,
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

#[derive(Template)]
#[template(path = "vector_tb.vhd")]
struct VhdlTb<'a> {
    tb: &'a str,
    module: &'a str,
    vectors: &'a str,
    has_reset: bool,
    inputs: &'a [Port],
    outputs: &'a [Port],
}

#[derive(Template)]
#[template(path = "vector_tb.v")]
struct VerilogTb<'a> {
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

/// The rendered files of a testbench: (file name, contents).
pub struct TestbenchFiles {
    pub vhdl_tb: String,
    pub verilog_tb: String,
    pub vectors_txt: String,
    pub vectors_hex: String,
    pub tb_name: String,
}

pub fn render(m: &Module, t: &Transcript) -> TestbenchFiles {
    let tb_name = format!("{}_tb", m.name);
    let in_ids: Vec<(String, SigId)> = m.inputs.iter().map(|&i| (m.sig(i).name.clone(), i)).collect();
    // Verilog vector word, most significant first: [rst] inputs… outputs…
    let (outputs, after_out) = ports(m, &m.outputs, 0);
    let (inputs, after_in) = ports(m, &in_ids, after_out);
    let has_reset = m.has_reset();
    let total_width = after_in + has_reset as u32;
    let out_tys: Vec<Ty> = m.outputs.iter().map(|(_, i)| m.sig(*i).ty).collect();
    let in_tys: Vec<Ty> = m.inputs.iter().map(|&i| m.sig(i).ty).collect();
    let mut txt = String::new();
    let mut hex = String::new();
    for (st, out) in t.stimuli.iter().zip(&t.outputs) {
        let mut fields: Vec<String> = Vec::new();
        let mut word = num_word::Word::default();
        if has_reset {
            fields.push(if st.reset { "1".into() } else { "0".into() });
            word.push(st.reset as u128, 1);
        }
        for (ty, v) in in_tys.iter().zip(&st.inputs) {
            fields.push(crate::rtl::emit::bit_string(ty.wrap(*v), ty.width));
            word.push(ty.wrap(*v), ty.width);
        }
        for (ty, v) in out_tys.iter().zip(out) {
            fields.push(crate::rtl::emit::bit_string(*v, ty.width));
            word.push(*v, ty.width);
        }
        txt.push_str(&fields.join(" "));
        txt.push('\n');
        hex.push_str(&word.hex(total_width));
        hex.push('\n');
    }
    let vhdl_tb =
        VhdlTb { tb: &tb_name, module: &m.name, vectors: "vectors.txt", has_reset, inputs: &inputs, outputs: &outputs }
            .render()
            .expect("testbench template renders");
    let verilog_tb = VerilogTb {
        tb: &tb_name,
        module: &m.name,
        vectors: "vectors.hex",
        has_reset,
        reset_bit: total_width - 1,
        inputs: &inputs,
        outputs: &outputs,
        total_width,
        count: t.stimuli.len(),
    }
    .render()
    .expect("testbench template renders");
    TestbenchFiles {
        vhdl_tb: vhdl_tb + "\n",
        verilog_tb: verilog_tb + "\n",
        vectors_txt: txt,
        vectors_hex: hex,
        tb_name,
    }
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
