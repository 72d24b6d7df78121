// Sub-tick timer of the encoder emulators (shared by the four channels: they all start at the
// same ALL with the same S and D). After `start` at clock edge T0 it raises `tick` during the
// clock before each edge T0 + k*D, k = 1..S, so the emulators step exactly at T0 + k*D
// (spec15 §3; io::PulseSegment::EdgeTimeNs). Then it idles until the next start.
// Requires D >= 4 and S >= 1 (INIT refuses anything else).
module subtick_timer (
  input  wire        clk,
  input  wire        clr,         // RESET / INIT / power-on: stop
  input  wire        start,       // the ALL's processing edge T0
  input  wire [15:0] subticks,    // S
  input  wire [15:0] clock_div,   // D
  output reg         tick
);
  reg [15:0] clocks_left;  // clocks until the edge before the next sub-tick edge
  reg [15:0] ticks_left;   // sub-ticks still to come in this period
  reg        active;

  always @(posedge clk) begin
    tick <= 1'b0;
    if (clr) begin
      active <= 1'b0;
    end else if (start) begin
      // Counting D-2, D-3, ..., 0 puts the first tick in the clock before edge T0 + D.
      clocks_left <= clock_div - 16'd2;
      ticks_left  <= subticks;
      active      <= 1'b1;
    end else if (active) begin
      if (clocks_left == 16'd0) begin
        tick        <= 1'b1;
        clocks_left <= clock_div - 16'd1;
        ticks_left  <= ticks_left - 16'd1;
        if (ticks_left == 16'd1) active <= 1'b0;
      end else begin
        clocks_left <= clocks_left - 16'd1;
      end
    end
  end
endmodule
