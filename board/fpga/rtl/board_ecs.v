// The ECS image's board logic (icoboard): four PWM generators driven by ALL's PWM words, four
// quadrature decoders whose counts ALL samples, and the digital pins. Mirrors the kIcoboard
// branches of io::EmulatedFpga. INIT is accepted iff step_ns >= 10 (spec15 §2); no divider.
module board_ecs (
  input  wire        clk,
  input  wire        rst,
  input  wire        clr,
  input  wire        init_go,
  output reg         init_done,
  output reg         init_ok,
  output wire [15:0] init_divider,
  input  wire        all_go,
  input  wire [63:0] payload,       // request bytes 2..9 (INIT: step, divider; ALL: PWM words)
  output wire [63:0] pwm_words,     // commanded PWM, pin_out
  output wire [63:0] enc_words,     // counts sampled at the last ALL, pin_in
  output wire        pulse_limit,
  output wire [3:0]  pwm_out,
  output wire [3:0]  pwm_dir,
  input  wire [3:0]  enc_a,
  input  wire [3:0]  enc_b,
  input  wire [3:0]  pin_in,
  output reg  [3:0]  pin_out
);
  wire [3:0] pin_s;

  assign init_divider = 16'd0;
  assign pulse_limit  = 1'b0;

  // step_ns >= 10, registered while the request is stable (it is from the engine's take on).
  reg step_ok;
  always @(posedge clk) begin
    step_ok   <= (payload[63:36] != 28'd0) || (payload[35:32] >= 4'd10);
    init_done <= init_go;
    if (init_go) init_ok <= step_ok;
  end

  genvar c;
  generate
    for (c = 0; c < 4; c = c + 1) begin : channel
      wire [15:0] request_word = payload[63 - 16 * c -: 16];
      reg  [11:0] magnitude;    // io::EmulatedFpga::pwm_values_ (0..2048)
      reg         negative;
      wire [13:0] count;
      reg  [13:0] count_sampled;

      sync2 u_sync_pin (.clk(clk), .d(pin_in[c]), .q(pin_s[c]));

      always @(posedge clk) begin
        if (clr) begin
          magnitude  <= 12'd0;
          negative   <= 1'b0;
          pin_out[c] <= 1'b0;
        end else if (all_go) begin
          magnitude  <= request_word[11:0];  // checked <= 2048 by the frame engine
          negative   <= request_word[15] && (request_word[13:0] != 14'd0);
          pin_out[c] <= request_word[14];
        end
      end

      pwm_generator u_generator (
        .clk(clk), .rst(rst), .magnitude(magnitude), .negative(negative),
        .pwm_out(pwm_out[c]), .pwm_dir(pwm_dir[c])
      );

      quad_decoder u_decoder (
        .clk(clk), .clr(clr), .enc_a(enc_a[c]), .enc_b(enc_b[c]), .count(count)
      );

      always @(posedge clk) begin
        if (clr) count_sampled <= 14'd0;
        else if (all_go) count_sampled <= count;
      end

      assign pwm_words[63 - 16 * c -: 16] = {negative, pin_out[c], 2'b00, magnitude};
      assign enc_words[63 - 16 * c -: 16] = {1'b0, pin_s[c], count_sampled};
    end
  endgenerate
endmodule
