// Quadrature decoder of the ECS image (io::QuadratureReader): A and B pass two-flop
// synchronisers, every state change counts (4x decoding) into a 14-bit counter, up when
// A leads B. A jump of two states (both lines changed between two samples) has no direction
// and is ignored, as the model does.
module quad_decoder (
  input  wire        clk,
  input  wire        clr,         // RESET / INIT / power-on: count 0
  input  wire        enc_a,
  input  wire        enc_b,
  output reg  [13:0] count
);
  wire       a_s, b_s;
  reg  [1:0] previous;  // state index of the last sample

  sync2 u_sync_a (.clk(clk), .d(enc_a), .q(a_s));
  sync2 u_sync_b (.clk(clk), .d(enc_b), .q(b_s));

  // 00 -> 0, A -> 1, AB -> 2, B -> 3 (Gray to binary).
  wire [1:0] state = {b_s, a_s ^ b_s};
  wire [1:0] step  = state - previous;

  always @(posedge clk) begin
    previous <= state;
    if (clr) count <= 14'd0;
    else if (step == 2'd1) count <= count + 14'd1;
    else if (step == 2'd3) count <= count - 14'd1;
  end
endmodule
