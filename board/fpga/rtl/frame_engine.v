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

  // The field checks in two registered stages (the request is stable from take on, the CHECK
  // state comes 12 clocks later), so no long compare chain ends in CHECK's many enables.
  // Stage 1: per-word primitives and the opcode's class.
  reg [3:0] word_zero, word_pwm_ok, word_enc_ok, addressed;
  reg       none_r, pwm_r, enc_r, op_ok_r, status_ok_r;
  always @(posedge clk) begin
    word_zero   <= {w3 == 16'd0, w2 == 16'd0, w1 == 16'd0, w0 == 16'd0};
    word_pwm_ok <= {w3[13:0] <= 14'd2048, w2[13:0] <= 14'd2048,   // magnitude <= 2048
                    w1[13:0] <= 14'd2048, w0[13:0] <= 14'd2048};
    word_enc_ok <= {!w3[15], !w2[15], !w1[15], !w0[15]};          // reserved bit
    addressed   <= per_channel ? selected : 4'b1111;
    none_r      <= none_class;
    pwm_r       <= pwm_class;
    enc_r       <= enc_class;
    op_ok_r     <= (op <= OP_TEST);
    status_ok_r <= (status == 8'd0);
  end
  // Stage 2: io::Decode's verdict without the CRC (S_CRC computes that meanwhile). A word not
  // addressed by a per-channel opcode must be 0; an addressed one must pass its class's check.
  wire [3:0] words_pass = (~addressed & word_zero) |
                          (addressed & (pwm_r ? word_pwm_ok : enc_r ? word_enc_ok : 4'b1111));
  reg fields_ok;
  always @(posedge clk) begin
    fields_ok <= op_ok_r && status_ok_r && (none_r ? (&word_zero) : (&words_pass));
  end

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
  // The selected byte is registered before it enters the CRC step (the byte multiplexer and
  // the XOR tree together miss 100 MHz), so a pass takes 12 clocks: index 0 only loads.
  reg  [7:0] crc_data;
  always @(posedge clk) crc_data <= crc_byte;
  wire [7:0] crc_next;
  crc8 u_crc (.crc_in(crc), .data(crc_data), .crc_out(crc_next));

  // ---- the answer's bytes 2..9 ----------------------------------------------------------------
  // Opcode decodes, registered like fields_ok (the request is stable from take on), so the
  // BUILD state's payload multiplexer starts from flip-flops.
  reg [7:0] op_answered;     // the request's opcode, NOOP when byte 0 is not one (EmulatedFpga)
  reg       is_init, is_all, is_test, is_readback, is_enc_readback;
  reg [3:0] readback_mask;
  always @(posedge clk) begin
    op_answered     <= (op <= OP_TEST) ? op : OP_NOOP;
    is_init         <= (op == OP_INIT);
    is_all          <= (op == OP_ALL);
    is_test         <= (op == OP_TEST);
    is_readback     <= per_channel;
    is_enc_readback <= op[3];
    readback_mask   <= selected;
  end

  reg [63:0] answer_payload;
  always @(*) begin
    answer_payload = 64'd0;
    if (is_init) begin
      // A damaged INIT still encodes an InitAnswer: version 1, 4 channels, identity 0.
      answer_payload = {8'd1, 8'd4, rejected ? 8'd0 : IDENTITY, 8'd0, 16'd0, answer_divider};
    end else if (!rejected) begin
      if (is_all) begin
        if (initialised) answer_payload = (TWIN != 0) ? pwm_words : enc_words;
      end else if (is_test) begin
        answer_payload = payload;
      end else if (is_readback) begin
        answer_payload = (is_enc_readback ? enc_words : pwm_words) &
                         {{16{readback_mask[0]}}, {16{readback_mask[1]}},
                          {16{readback_mask[2]}}, {16{readback_mask[3]}}};
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
          if (index != 4'd0) crc <= crc_next;
          index <= index + 4'd1;
          if (index == 4'd11) state <= S_CHECK;
        end
        S_CHECK: begin
          rejected       <= 1'b0;
          init_rejected  <= 1'b0;
          answer_divider <= 16'd0;
          wait_left      <= 3'd1;
          state          <= S_WAIT;
          if ((crc ^ 8'hFF) != crc_rx || !fields_ok) begin
            rejected <= 1'b1;          // never act on a damaged request
          end else if (is_init) begin
            clr         <= 1'b1;
            init_go     <= 1'b1;
            initialised <= 1'b0;
            state       <= S_INIT;
          end else if (op_answered == OP_RESET) begin
            clr         <= 1'b1;
            initialised <= 1'b0;
            wait_left   <= 3'd2;       // let the board's status (pulse limit) clear
          end else if (is_all && initialised) begin
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
          if (index != 4'd0) crc <= crc_next;
          index <= index + 4'd1;
          if (index == 4'd11) state <= S_WRITE;
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
