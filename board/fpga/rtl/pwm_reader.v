// PWM reader of the twin image (thesis §4.2; io::PwmReaderValue). The input and the direction
// line pass two-flop synchronisers; a free-running 12-bit counter cuts time into 4096-clock
// periods (the generator's period, 24.4 kHz); the high clocks of each period are counted and at
// the wrap value = min(high / 2, 2047) (11 bits), with the sign of the synchronised direction
// line at that moment (negative only when value != 0). For a steady duty any 4096-clock window
// holds the same number of high clocks, so the reader needs no phase relation to the generator.
module pwm_reader (
  input  wire        clk,
  input  wire        rst,
  input  wire        pwm_in,
  input  wire        dir_in,
  output reg  [10:0] value,
  output reg         negative
);
  wire       pwm_s, dir_s;
  reg [11:0] period;
  reg [12:0] high;       // high clocks so far in this period (<= 4095 before the last clock)

  sync2 u_sync_pwm (.clk(clk), .d(pwm_in), .q(pwm_s));
  sync2 u_sync_dir (.clk(clk), .d(dir_in), .q(dir_s));

  wire [12:0] total = high + {12'd0, pwm_s};  // including the period's last clock

  always @(posedge clk) begin
    if (rst) begin
      period   <= 12'd0;
      high     <= 13'd0;
      value    <= 11'd0;
      negative <= 1'b0;
    end else begin
      period <= period + 12'd1;
      if (period == 12'hFFF) begin
        value    <= total[12] ? 11'd2047 : total[11:1];
        negative <= dir_s && (total[12:1] != 12'd0);
        high     <= 13'd0;
      end else begin
        high <= total;
      end
    end
  end
endmodule
