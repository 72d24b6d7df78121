// One channel of the twin image's quadrature encoder emulator (thesis §2.2.1, §4.2.4,
// Table 4.1; io::EncoderEmulator). Everything on clk; nothing is clocked by a generated signal
// (the race conditions of thesis §4.2.4 came from exactly that).
//
// At `start` (edge T0, the ALL's processing clock) the channel plans the move from the
// position reached so far to `target` (both 14-bit relative counts):
//   m = (target - reached) mod 2^14
//   m = 0            -> nothing
//   1 <= m <= 8191   -> m pulses up      (Table 4.1 case A, and case D: negative with overflow)
//   8192 <= m        -> 2^14 - m down    (case B, and case C: positive with overflow)
// N = min(plan, S, 8191); `limit` (PULSE_LIMIT) when plan > N. 8191, not 8192: a move of half
// the 14-bit range (m = 8192) reads the same as its opposite after the wrap, so it is never
// emitted in one period, whatever S (io::MaxPulsesPerPeriod); the last count follows in the next
// period, flagged like any change over the limit. The pulses are spread over the S
// sub-ticks with a division-free accumulator: acc += N each sub-tick, and when acc >= S one edge
// is emitted and acc -= S, so edge j comes at sub-tick ceil(j*S/N) (io::PulseSegment).
//
// The plan is pipelined over the clocks T0+1, T0+2 (the first sub-tick edge is T0+D >= T0+4),
// and the values each sub-tick needs (the next position, its A/B levels, acc+N and acc+N-S) are
// registered one clock after anything they depend on changes, so no long path meets a tick.
module encoder_emulator (
  input  wire        clk,
  input  wire        clr,          // RESET / INIT / power-on: position 0, idle
  input  wire        start,        // ALL processed at this edge (T0)
  input  wire [13:0] target,       // requested position, valid with start
  input  wire [15:0] subticks,     // S
  input  wire        tick,         // from subtick_timer: step at the coming edge
  output reg         enc_a,
  output reg         enc_b,
  output reg         limit,        // valid from T0+2 until the next start
  output reg  [13:0] end_position  // reached + dir*N, valid from T0+3 (ENC read-back)
);
  reg [13:0] position;             // what the A/B lines show
  reg [13:0] target_r;
  reg [13:0] diff_up;              // (target - reached) mod 2^14
  reg [13:0] diff_down;            // (reached - target) mod 2^14
  reg [13:0] pulses;               // N (<= 8191)
  reg [12:0] most;                 // min(S, 8191): the most pulses one period emits
  reg        up;                   // direction of this period
  reg [16:0] acc;                  // < S
  reg [17:0] acc_minus;            // acc + N - S (negative: no edge at the next tick)
  reg [16:0] acc_plus;             // acc + N
  reg [13:0] next_position;
  reg        next_a, next_b;
  reg [2:0]  plan_stage;           // bit k set in the clock before edge T0+k+1

  // Levels of the position: mod 4 = 0: 00, 1: A, 2: AB, 3: B (A leads B counting up).
  function [1:0] levels(input [1:0] p);
    levels = {p[1] ^ p[0], p[1]};
  endfunction

  wire emit = tick && !acc_minus[17];
  wire [13:0] plan = diff_up[13] ? diff_down : diff_up;  // diff_up >= 8192: go down

  always @(posedge clk) begin
    if (clr) begin
      position     <= 14'd0;
      enc_a        <= 1'b0;
      enc_b        <= 1'b0;
      pulses       <= 14'd0;
      acc          <= 17'd0;
      limit        <= 1'b0;
      end_position <= 14'd0;
      up           <= 1'b1;
      plan_stage   <= 3'b000;
    end else begin
      // Sub-tick: step the lines (the old period's last tick may coincide with T0: it counts).
      if (emit) begin
        position <= next_position;
        enc_a    <= next_a;
        enc_b    <= next_b;
      end
      if (start) begin
        acc        <= 17'd0;
        pulses     <= 14'd0;    // nothing to emit until the plan is in (no tick before T0+D)
        target_r   <= target;
        plan_stage <= 3'b001;
      end else begin
        if (tick) acc <= acc_minus[17] ? acc_plus : acc_minus[16:0];
        plan_stage <= {plan_stage[1:0], 1'b0};
      end
      // T0+1: position is the reached position until T0+D.
      if (plan_stage[0]) begin
        diff_up   <= target_r - position;
        diff_down <= position - target_r;
      end
      // T0+2: Table 4.1 and the pulse-rate limit.
      if (plan_stage[1]) begin
        up <= !diff_up[13];
        if (plan > {1'b0, most}) begin
          pulses <= {1'b0, most};
          limit  <= 1'b1;
        end else begin
          pulses <= plan;
          limit  <= 1'b0;
        end
      end
      // T0+3: where this period ends (io::EncoderEmulator::PositionAt(t + step)).
      if (plan_stage[2]) end_position <= up ? position + pulses : position - pulses;
    end
    // S changes only at INIT, at least one whole transfer (~300 clocks) before an ALL uses it.
    most          <= (subticks > 16'd8191) ? 13'd8191 : subticks[12:0];
    // Registered look-ahead for the next tick (ticks are >= 4 clocks apart).
    acc_plus      <= acc + {3'b000, pulses};
    acc_minus     <= {1'b0, acc} + {4'b0000, pulses} - {2'b00, subticks};
    next_position <= up ? position + 14'd1 : position - 14'd1;
    {next_a, next_b} <= levels(up ? position[1:0] + 2'd1 : position[1:0] - 2'd1);
  end
endmodule
