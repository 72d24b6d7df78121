// Two-flop synchroniser for one asynchronous input (SPI chip select, PWM, A/B and pin lines).
// The first flop may go metastable; the second gives it a full 10 ns clock period to settle.
module sync2 (
  input  wire clk,
  input  wire d,
  output wire q
);
  reg [1:0] stages = 2'b00;

  always @(posedge clk) stages <= {stages[0], d};

  assign q = stages[1];
endmodule
