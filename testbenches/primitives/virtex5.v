// Stand-ins for the Virtex-5 primitives the ML509 top uses, for simulation and lint only (ISE
// has the real ones in UNISIM): the ports and the parameters set of PLL_BASE and BUFG;
// CLKOUT0 follows CLKIN and LOCKED rises after eight CLKIN edges.
/* verilator lint_off UNUSED */
/* verilator lint_off DECLFILENAME */
module PLL_BASE #(
    parameter real CLKIN_PERIOD = 0.0, parameter integer DIVCLK_DIVIDE = 1,
    parameter integer CLKFBOUT_MULT = 1, parameter integer CLKOUT0_DIVIDE = 1,
    parameter COMPENSATION = "SYSTEM_SYNCHRONOUS"
) (
    input wire CLKIN, input wire CLKFBIN, input wire RST,
    output wire CLKFBOUT, output wire CLKOUT0, output wire CLKOUT1, output wire CLKOUT2,
    output wire CLKOUT3, output wire CLKOUT4, output wire CLKOUT5, output wire LOCKED
);
    reg [3:0] edges = 4'd0;
    always @(posedge CLKIN) if (!edges[3]) edges <= edges + 4'd1;
    assign CLKFBOUT = CLKIN;
    assign CLKOUT0 = CLKIN;
    assign {CLKOUT1, CLKOUT2, CLKOUT3, CLKOUT4, CLKOUT5} = 5'b0;
    assign LOCKED = edges[3];
endmodule

module BUFG (input wire I, output wire O);
    assign O = I;
endmodule
/* verilator lint_on UNUSED */
