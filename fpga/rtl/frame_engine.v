// Frame engine: checks each request exactly as io::Decode(Direction::kRequest, image) does,
// acts on it as io::EmulatedFpga::Exchange does, and builds the encoded answer (CRC included)
// for the answer register, which it writes only while CS is high (spec15 §1, §3).
// Image-specific work (INIT's range check, ALL's data, the read-back words) is the board's:
// board_twin or board_ecs. Byte i of a frame is bits [95-8i -: 8].
//
// Timing from the request's last SCLK edge: synchroniser ~3 clocks, request CRC 11, check 1,
// INIT (twin) ~70 or ALL 6, build 1, answer CRC 11, write 1: under 110 clocks (< 150, §1).
module frame_engine #(
  parameter TWIN = 0,                 // 1: icoboard_inverse (ALL request carries ENC words)
  parameter [7:0] IDENTITY = 8'd11
) (
  input  wire        clk,
  input  wire        rst,
  // SPI slave
  input  wire        pending,
  output wire        take,
  input  wire [95:0] request,
  input  wire        cs_idle,
  output reg  [95:0] answer,
  // board
  output reg         clr,             // io::EmulatedFpga::ResetState (RESET, INIT)
  output reg         init_go,         // check INIT's parameters (request bytes 2..9)
  input  wire        init_done,
  input  wire        init_ok,
  input  wire [15:0] init_divider,    // accepted divider for the answer (0 on the ECS image)
  output reg         all_go,          // act on ALL (request bytes 2..9), sample the inputs
  output wire [63:0] payload,         // request bytes 2..9
  input  wire [63:0] pwm_words,       // PWM channel words: ALL answer (twin), PWM c read-back
  input  wire [63:0] enc_words,       // ENC channel words: ALL answer (ECS), ENC c read-back
  input  wire        pulse_limit
);
  localparam [7:0] OP_NOOP = 8'd0, OP_INIT = 8'd1, OP_RESET = 8'd2, OP_ALL = 8'd3,
                   OP_TEST = 8'd12;

  localparam [3:0] S_IDLE = 4'd0, S_CRC = 4'd1, S_CHECK = 4'd2, S_INIT = 4'd3, S_WAIT = 4'd4,
                   S_BUILD = 4'd5, S_ACRC = 4'd6, S_WRITE = 4'd7;

  reg  [3:0]  state;
  reg  [3:0]  index;          // byte index for the CRC passes
  reg  [7:0]  crc;
  reg  [2:0]  wait_left;
  reg         initialised;
  reg         rejected;
  reg         init_rejected;
  reg  [15:0] answer_divider;
  reg  [87:0] build;         // the answer's bytes 0..10

  assign take    = (state == S_IDLE) && pending;
  assign payload = request[79:16];

  // ---- request fields -----------------------------------------------------------------------
  wire [7:0]  op     = request[95:88];
  wire [7:0]  status = request[15:8];
  wire [7:0]  crc_rx = request[7:0];
  wire [15:0] w0 = payload[63:48], w1 = payload[47:32], w2 = payload[31:16], w3 = payload[15:0];
  wire [3:0]  selected = 4'b0001 << op[1:0];   // the channel of a per-channel opcode

  // io::PayloadOf for Direction::kRequest on this image.
  wire per_channel = (op >= 8'd4) && (op <= 8'd11);
  wire pwm_class   = (op >= 8'd4 && op <= 8'd7) || (op == OP_ALL && TWIN == 0);
  wire enc_class   = (op >= 8'd8 && op <= 8'd11) || (op == OP_ALL && TWIN != 0);
  wire none_class  = (op == OP_NOOP) || (op == OP_RESET);

  // Per channel: "not addressed by a per-channel opcode, so must be 0", or the field check.
  function word_ok(input [15:0] w, input addressed, input pwm, input enc);
    if (!addressed)  word_ok = (w == 16'd0);
    else if (pwm)    word_ok = (w[13:0] <= 14'd2048);   // magnitude <= kPwmMagnitudeMax
    else if (enc)    word_ok = !w[15];                  // reserved bit
    else             word_ok = 1'b1;
  endfunction

  wire [3:0] addressed = per_channel ? selected : 4'b1111;
  wire words_ok = word_ok(w0, addressed[0], pwm_class, enc_class) &
                  word_ok(w1, addressed[1], pwm_class, enc_class) &
                  word_ok(w2, addressed[2], pwm_class, enc_class) &
                  word_ok(w3, addressed[3], pwm_class, enc_class);
  wire payload_ok = none_class ? (payload == 64'd0) : words_ok;

  // ---- CRC over bytes 0..10 of the request (S_CRC) or of the answer being built (S_ACRC) ------
  wire [87:0] crc_frame = (state == S_ACRC) ? build : request[95:8];  // bytes 0..10
  reg  [7:0]  crc_byte;
  always @(*) begin
    case (index)
      4'd0:  crc_byte = crc_frame[87:80];
      4'd1:  crc_byte = crc_frame[79:72];
      4'd2:  crc_byte = crc_frame[71:64];
      4'd3:  crc_byte = crc_frame[63:56];
      4'd4:  crc_byte = crc_frame[55:48];
      4'd5:  crc_byte = crc_frame[47:40];
      4'd6:  crc_byte = crc_frame[39:32];
      4'd7:  crc_byte = crc_frame[31:24];
      4'd8:  crc_byte = crc_frame[23:16];
      4'd9:  crc_byte = crc_frame[15:8];
      default: crc_byte = crc_frame[7:0];
    endcase
  end
  wire [7:0] crc_next;
  crc8 u_crc (.crc_in(crc), .data(crc_byte), .crc_out(crc_next));

  // ---- the answer's bytes 2..9 ----------------------------------------------------------------
  // op_answered: the request's opcode, NOOP when byte 0 is not an opcode (EmulatedFpga).
  wire [7:0] op_answered = (op <= OP_TEST) ? op : OP_NOOP;
  reg  [63:0] answer_payload;
  always @(*) begin
    answer_payload = 64'd0;
    if (op_answered == OP_INIT) begin
      // A damaged INIT still encodes an InitAnswer: version 1, 4 channels, identity 0.
      answer_payload = {8'd1, 8'd4, rejected ? 8'd0 : IDENTITY, 8'd0, 16'd0, answer_divider};
    end else if (!rejected) begin
      if (op == OP_ALL) begin
        if (initialised) answer_payload = (TWIN != 0) ? pwm_words : enc_words;
      end else if (op == OP_TEST) begin
        answer_payload = payload;
      end else if (per_channel) begin
        answer_payload = (op[3] ? enc_words : pwm_words) &
                         {{16{selected[0]}}, {16{selected[1]}}, {16{selected[2]}}, {16{selected[3]}}};
      end
    end
  end
  wire [7:0] answer_status = {4'd0, init_rejected, pulse_limit, rejected, initialised};

  always @(posedge clk) begin
    clr     <= 1'b0;
    init_go <= 1'b0;
    all_go  <= 1'b0;
    if (rst) begin
      state          <= S_IDLE;
      answer         <= 96'd0;   // all-zero MISO: the host reads "idle"
      initialised    <= 1'b0;
      rejected       <= 1'b0;
      init_rejected  <= 1'b0;
      answer_divider <= 16'd0;
      clr            <= 1'b1;
    end else begin
      case (state)
        S_IDLE: if (take) begin         // spi_slave copies holding into `request` now
          crc   <= 8'hFF;
          index <= 4'd0;
          state <= S_CRC;
        end
        S_CRC: begin
          crc   <= crc_next;
          index <= index + 4'd1;
          if (index == 4'd10) state <= S_CHECK;
        end
        S_CHECK: begin
          rejected       <= 1'b0;
          init_rejected  <= 1'b0;
          answer_divider <= 16'd0;
          wait_left      <= 3'd1;
          state          <= S_WAIT;
          if ((crc ^ 8'hFF) != crc_rx || op > OP_TEST || status != 8'd0 || !payload_ok) begin
            rejected <= 1'b1;          // never act on a damaged request
          end else if (op == OP_INIT) begin
            clr         <= 1'b1;
            init_go     <= 1'b1;
            initialised <= 1'b0;
            state       <= S_INIT;
          end else if (op == OP_RESET) begin
            clr         <= 1'b1;
            initialised <= 1'b0;
            wait_left   <= 3'd2;       // let the board's status (pulse limit) clear
          end else if (op == OP_ALL && initialised) begin
            all_go    <= 1'b1;
            wait_left <= 3'd6;         // encoder plan (limit, end position) and samples settle
          end
        end
        S_INIT: if (init_done) begin
          initialised    <= init_ok;
          init_rejected  <= !init_ok;
          answer_divider <= init_ok ? init_divider : 16'd0;
          wait_left      <= 3'd1;
          state          <= S_WAIT;
        end
        S_WAIT: begin
          wait_left <= wait_left - 3'd1;
          if (wait_left == 3'd1) state <= S_BUILD;
        end
        S_BUILD: begin
          build <= {op_answered, request[87:80], answer_payload, answer_status};
          crc   <= 8'hFF;
          index <= 4'd0;
          state <= S_ACRC;
        end
        S_ACRC: begin
          crc   <= crc_next;
          index <= index + 4'd1;
          if (index == 4'd10) state <= S_WRITE;
        end
        S_WRITE: if (cs_idle) begin     // never change MISO during a transfer
          answer <= {build, crc ^ 8'hFF};
          state  <= S_IDLE;
        end
        default: state <= S_IDLE;
      endcase
    end
  end
endmodule
