// Restoring divider, one quotient bit per clock: quotient = dividend / divisor (unsigned,
// 32 / 16 bits) in 32 clocks after `start`. Only INIT divides (step_ns / 10, then / D), so a
// small sequential divider beats a combinational one that would never meet 100 MHz.
// divisor must not be 0 (the caller checks).
module seq_divider (
  input  wire        clk,
  input  wire        start,
  input  wire [31:0] dividend,
  input  wire [15:0] divisor,
  output reg         done,       // one-clock pulse; quotient valid from then on
  output reg  [31:0] quotient
);
  reg [15:0] remainder;
  reg [15:0] divisor_r;
  reg [5:0]  steps_left = 6'd0;

  // Shift the next dividend bit (kept in the top of `quotient`) into the remainder, subtract.
  wire [16:0] shifted = {remainder, quotient[31]};
  // trial[16] is 0 whenever trial is used (shifted < 2 * divisor), hence the waiver.
  /* verilator lint_off UNUSEDSIGNAL */
  wire [17:0] trial   = {1'b0, shifted} - {2'b00, divisor_r};
  /* verilator lint_on UNUSEDSIGNAL */

  always @(posedge clk) begin
    done <= 1'b0;
    if (start) begin
      quotient   <= dividend;
      remainder  <= 16'd0;
      divisor_r  <= divisor;
      steps_left <= 6'd32;
    end else if (steps_left != 6'd0) begin
      if (!trial[17]) begin
        remainder <= trial[15:0];   // < divisor, so 16 bits hold it
        quotient  <= {quotient[30:0], 1'b1};
      end else begin
        remainder <= shifted[15:0]; // shifted < divisor here, so bit 16 is 0
        quotient  <= {quotient[30:0], 1'b0};
      end
      steps_left <= steps_left - 6'd1;
      if (steps_left == 6'd1) done <= 1'b1;
    end
  end
endmodule
