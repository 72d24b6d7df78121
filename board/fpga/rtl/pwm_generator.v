// PWM generator of the ECS image: 24.4 kHz (100 MHz / 4096). A free-running 12-bit counter;
// the magnitude m (0..2048) and the direction are latched when the counter wraps to 0, so a new
// value never cuts a period short (no glitch on the motor driver); the output is high while
// counter < 2m (m = 2048: always high). dir = 1 for negative, 0 when m = 0.
module pwm_generator (
  input  wire        clk,
  input  wire        rst,
  input  wire [11:0] magnitude,   // 0..2048
  input  wire        negative,
  output reg         pwm_out,
  output reg         pwm_dir
);
  reg [11:0] counter;
  reg [11:0] m_latched;
  reg        neg_latched;

  always @(posedge clk) begin
    if (rst) begin
      counter     <= 12'd0;
      m_latched   <= 12'd0;
      neg_latched <= 1'b0;
      pwm_out     <= 1'b0;
      pwm_dir     <= 1'b0;
    end else begin
      counter <= counter + 12'd1;
      if (counter == 12'hFFF) begin
        m_latched   <= magnitude;
        neg_latched <= negative && (magnitude != 12'd0);
      end
      pwm_out <= {1'b0, counter} < {m_latched, 1'b0};
      pwm_dir <= neg_latched;
    end
  end
endmodule
