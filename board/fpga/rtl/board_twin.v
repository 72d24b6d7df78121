// The twin image's board logic (icoboard_inverse): INIT's range check and the encoder clock
// divider, four PWM readers, four encoder emulators with their shared sub-tick timer, and the
// digital pins. Mirrors the kIcoboardInverse branches of io::EmulatedFpga.
module board_twin (
  input  wire        clk,
  input  wire        rst,
  input  wire        clr,
  input  wire        init_go,
  output wire        init_done,
  output wire        init_ok,
  output wire [15:0] init_divider,
  input  wire        all_go,
  input  wire [63:0] payload,       // request bytes 2..9 (ALL: four ENC words)
  output wire [63:0] pwm_words,     // measured PWM (latched at the last ALL), pin_in
  output wire [63:0] enc_words,     // end-of-period targets, pin_out
  output wire        pulse_limit,
  input  wire [3:0]  pwm_in,
  input  wire [3:0]  pwm_dir_in,
  output wire [3:0]  enc_a,
  output wire [3:0]  enc_b,
  input  wire [3:0]  pin_in,
  output reg  [3:0]  pin_out
);
  wire [15:0] subticks, clock_div_new, subticks_new;
  reg  [15:0] subticks_r, clock_div_r;
  wire        tick;
  wire [3:0]  limit;
  wire [3:0]  pin_s;

  init_check u_init (
    .clk(clk), .rst(rst), .go(init_go), .step_ns(payload[63:32]), .divider(payload[31:0]),
    .done(init_done), .ok(init_ok), .subticks(subticks_new), .clock_div(clock_div_new)
  );
  assign init_divider = clock_div_new;

  // S and D of the accepted INIT (RESET stops the timer; the next INIT sets them again).
  always @(posedge clk) begin
    if (init_done && init_ok) begin
      subticks_r  <= subticks_new;
      clock_div_r <= clock_div_new;
    end
  end
  assign subticks = subticks_r;

  subtick_timer u_timer (
    .clk(clk), .clr(clr), .start(all_go), .subticks(subticks_r), .clock_div(clock_div_r),
    .tick(tick)
  );

  genvar c;
  generate
    for (c = 0; c < 4; c = c + 1) begin : channel
      wire [14:0] request_word = payload[62 - 16 * c -: 15];  // bit 15 is reserved (checked 0)
      wire [10:0] reader_value;
      wire        reader_negative;
      reg  [10:0] value;        // io::EmulatedFpga::pwm_values_: sampled at ALL
      reg         negative;
      wire [13:0] end_position;

      sync2 u_sync_pin (.clk(clk), .d(pin_in[c]), .q(pin_s[c]));

      pwm_reader u_reader (
        .clk(clk), .rst(rst), .pwm_in(pwm_in[c]), .dir_in(pwm_dir_in[c]),
        .value(reader_value), .negative(reader_negative)
      );

      always @(posedge clk) begin
        if (clr) begin
          value    <= 11'd0;
          negative <= 1'b0;
        end else if (all_go) begin
          value    <= reader_value;
          negative <= reader_negative;
        end
      end

      encoder_emulator u_emulator (
        .clk(clk), .clr(clr), .start(all_go), .target(request_word[13:0]),
        .subticks(subticks), .tick(tick), .enc_a(enc_a[c]), .enc_b(enc_b[c]),
        .limit(limit[c]), .end_position(end_position)
      );

      always @(posedge clk) begin
        if (clr) pin_out[c] <= 1'b0;
        else if (all_go) pin_out[c] <= request_word[14];
      end

      assign pwm_words[63 - 16 * c -: 16] = {negative, pin_s[c], 3'b000, value};
      assign enc_words[63 - 16 * c -: 16] = {1'b0, pin_out[c], end_position};
    end
  endgenerate

  assign pulse_limit = |limit;
endmodule
