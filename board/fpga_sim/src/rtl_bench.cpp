#include "hiltwin/fpga_sim/rtl_bench.h"

#include <verilated.h>

#include <algorithm>

#include "Vicoboard.h"
#include "Vicoboard_inverse.h"

namespace hiltwin::fpga_sim {
namespace {

constexpr std::uint32_t kPwmPeriod = 4096;

template <typename Top>
void EvalTop(void* top) {
  static_cast<Top*>(top)->eval();
}

}  // namespace

/// One verilated image: the model behind raw pointers to its ports (no virtual call, no
/// std::function on the per-clock path). Ports a top does not have stay null.
struct RtlBench::Board {
  std::unique_ptr<VerilatedContext> context = std::make_unique<VerilatedContext>();
  std::shared_ptr<void> top;
  void (*eval)(void*) = nullptr;
  CData* clk = nullptr;
  CData* sclk = nullptr;
  CData* mosi = nullptr;
  CData* cs_n = nullptr;
  CData* miso = nullptr;
  CData* pin_in = nullptr;
  CData* pin_out = nullptr;
  CData* pwm_in = nullptr;      // twin
  CData* pwm_dir_in = nullptr;  // twin
  CData* pwm_out = nullptr;     // ECS
  CData* pwm_dir = nullptr;     // ECS
  CData* enc_a = nullptr;       // twin: out, ECS: in
  CData* enc_b = nullptr;

  void Eval() const noexcept { eval(top.get()); }

  template <typename Top>
  Top& Make() {
    auto made = std::make_shared<Top>(context.get(), "board");
    Top& t = *made;
    top = made;
    eval = &EvalTop<Top>;
    clk = &t.clk;
    sclk = &t.spi_sclk;
    mosi = &t.spi_mosi;
    cs_n = &t.spi_cs_n;
    miso = &t.spi_miso;
    pin_in = &t.pin_in;
    pin_out = &t.pin_out;
    enc_a = &t.enc_a;
    enc_b = &t.enc_b;
    return t;
  }

  static std::unique_ptr<Board> Twin() {
    auto board = std::make_unique<Board>();
    auto& t = board->Make<Vicoboard_inverse>();
    board->pwm_in = &t.pwm_in;
    board->pwm_dir_in = &t.pwm_dir_in;
    board->Idle();
    return board;
  }

  static std::unique_ptr<Board> Ecs() {
    auto board = std::make_unique<Board>();
    auto& t = board->Make<Vicoboard>();
    board->pwm_out = &t.pwm_out;
    board->pwm_dir = &t.pwm_dir;
    board->Idle();
    return board;
  }

  void Idle() const noexcept {
    *clk = 0;
    *sclk = 0;
    *mosi = 0;
    *cs_n = 1;
    *pin_in = 0;
    if (pwm_in != nullptr) {
      *pwm_in = 0;
      *pwm_dir_in = 0;
    } else {
      *enc_a = 0;
      *enc_b = 0;
    }
    Eval();
  }
};

RtlBench::RtlBench(bool twin, bool ecs, bool wired) : wired_(wired) {
  if (twin) twin_ = Board::Twin();
  if (ecs) ecs_ = Board::Ecs();
  if (wired_ && (!twin || !ecs)) wired_ = false;
  RunClocks(kPowerOnClocks);
}

RtlBench::~RtlBench() = default;

bool RtlBench::has(Slot slot) const noexcept {
  return slot == Slot::kTwin ? twin_ != nullptr : ecs_ != nullptr;
}

void RtlBench::ClockEdge(bool rising) noexcept {
  const CData level = rising ? 1 : 0;
  if (twin_) {
    *twin_->clk = level;
    twin_->Eval();
  }
  if (ecs_) {
    *ecs_->clk = level;
    ecs_->Eval();
  }
  clk_high_ = rising;
  if (rising) {
    ++clocks_;
    AfterRisingEdge();
  }
}

void RtlBench::AfterRisingEdge() noexcept {
  if (wired_) {
    // Registered outputs of this edge reach the other board's input flops at the next edge.
    *twin_->pwm_in = *ecs_->pwm_out;
    *twin_->pwm_dir_in = *ecs_->pwm_dir;
    *ecs_->enc_a = *twin_->enc_a;
    *ecs_->enc_b = *twin_->enc_b;
    *ecs_->pin_in = *twin_->pin_out;
    *twin_->pin_in = *ecs_->pin_out;
    if (*twin_->enc_a != wire_a_ || *twin_->enc_b != wire_b_) CheckWires(*twin_->enc_a, *twin_->enc_b);
  } else if (pwm_active_) {
    ApplyLoneInputs();
  }
  if (clocks_ >= feed_next_clock_) ServiceLineFeed();
  if (recording_) {
    if (twin_) Record(Slot::kTwin);
    if (ecs_) Record(Slot::kEcs);
  }
}

void RtlBench::ApplyLoneInputs() noexcept {
  pwm_phase_ = (pwm_phase_ + 1) & (kPwmPeriod - 1);
  std::uint8_t bits = 0;
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    if (pwm_phase_ < pwm_high_clocks_[c]) bits = static_cast<std::uint8_t>(bits | (1U << c));
  }
  *twin_->pwm_in = bits;
  *twin_->pwm_dir_in = pwm_dir_in_;
}

void RtlBench::CheckWires(std::uint8_t a, std::uint8_t b) noexcept {
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    const bool a_changed = ((unsigned{a} ^ unsigned{wire_a_}) >> c & 1U) != 0;
    const bool b_changed = ((unsigned{b} ^ unsigned{wire_b_}) >> c & 1U) != 0;
    if (!a_changed && !b_changed) continue;
    ++wire_.edges;
    if (a_changed && b_changed) ++wire_.illegal_transitions;
    if (clocks_ - wire_changed_at_[c] < 2) ++wire_.too_fast;
    wire_changed_at_[c] = clocks_;
  }
  wire_a_ = a;
  wire_b_ = b;
}

void RtlBench::Record(Slot slot) {
  auto& last = last_out_[static_cast<std::size_t>(slot)];
  for (std::size_t s = 0; s < last.size(); ++s) {
    const auto signal = static_cast<Signal>(s);
    const std::uint8_t value = Output(slot, signal);
    if (value != last[s]) {
      edges_.push_back(OutputEdge{clocks_ - 1, slot, signal, value});
      last[s] = value;
    }
  }
}

std::uint8_t RtlBench::Output(Slot slot, Signal signal) const noexcept {
  const Board* board = slot == Slot::kTwin ? twin_.get() : ecs_.get();
  if (board == nullptr) return 0;
  const bool twin = slot == Slot::kTwin;
  switch (signal) {
    case Signal::kEncA: return twin ? *board->enc_a : 0;
    case Signal::kEncB: return twin ? *board->enc_b : 0;
    case Signal::kPwm: return twin ? 0 : *board->pwm_out;
    case Signal::kPwmDir: return twin ? 0 : *board->pwm_dir;
    case Signal::kPinOut: return *board->pin_out;
  }
  return 0;
}

void RtlBench::RunUntil(std::int64_t t_ps) noexcept {
  // Rising edge k (1-based count clocks_) at (k-1)·10 ns, the falling edge 5 ns later.
  for (;;) {
    const std::int64_t next = clk_high_
                                  ? static_cast<std::int64_t>(clocks_ - 1) * kClockPs + kClockPs / 2
                                  : static_cast<std::int64_t>(clocks_) * kClockPs;
    if (next > t_ps) break;
    ClockEdge(!clk_high_);
  }
  if (t_ps > now_ps_) now_ps_ = t_ps;
}

void RtlBench::Transfer(Slot slot, const io::FrameBytes& mosi, io::FrameBytes& miso,
                        const TransferShape& shape) noexcept {
  Board* board = slot == Slot::kTwin ? twin_.get() : ecs_.get();
  if (board == nullptr) return;
  const std::int64_t half_ps = (500'000'000'000 + shape.sclk_hz / 2) / shape.sclk_hz;
  const std::int64_t t0 = now_ps_ + shape.lead_ps;
  auto bit_of = [&mosi](std::uint32_t i) -> CData {
    if (i >= io::kFrameBytes * 8) return 0;
    return static_cast<CData>((unsigned{mosi[i / 8]} >> (7U - i % 8U)) & 1U);
  };
  // One SPI edge at t: the clock edges before it run first; a clock edge at the same
  // picosecond is applied together with it (one evaluation of every board).
  auto spi_edge = [&](std::int64_t t, auto&& set) {
    RunUntil(t - 1);
    set();
    const std::int64_t next_clock = clk_high_
                                        ? static_cast<std::int64_t>(clocks_ - 1) * kClockPs + kClockPs / 2
                                        : static_cast<std::int64_t>(clocks_) * kClockPs;
    if (next_clock == t) {
      ClockEdge(!clk_high_);
    } else {
      board->Eval();
    }
    now_ps_ = t;
  };
  spi_edge(t0, [&] {
    *board->cs_n = 0;
    *board->mosi = bit_of(0);
  });
  for (std::uint32_t i = 0; i < shape.bits; ++i) {
    const std::int64_t rise = t0 + (2 * static_cast<std::int64_t>(i) + 1) * half_ps;
    spi_edge(rise, [&] {
      if (i < io::kFrameBytes * 8) {
        const auto mask = static_cast<std::uint8_t>(1U << (7 - i % 8));
        miso[i / 8] = static_cast<std::uint8_t>(*board->miso != 0 ? (miso[i / 8] | mask)
                                                                    : (miso[i / 8] & ~mask));
      }
      *board->sclk = 1;
    });
    spi_edge(rise + half_ps, [&] {
      *board->sclk = 0;
      *board->mosi = bit_of(i + 1);
    });
  }
  spi_edge(t0 + (2 * static_cast<std::int64_t>(shape.bits) + 1) * half_ps, [&] {
    *board->cs_n = 1;
    *board->mosi = 0;
  });
}

void RtlBench::SetPwmInput(std::size_t c, std::uint32_t high_clocks, bool negative) noexcept {
  pwm_high_clocks_[c] = high_clocks > kPwmPeriod ? kPwmPeriod : high_clocks;
  pwm_dir_in_ = static_cast<std::uint8_t>(negative ? (pwm_dir_in_ | (1U << c))
                                                   : (pwm_dir_in_ & ~(1U << c)));
  pwm_active_ = twin_ != nullptr && !wired_;
}

void RtlBench::SetEncoderInput(std::size_t c, bool a, bool b) noexcept {
  if (!ecs_ || wired_) return;
  const auto bit = static_cast<CData>(1U << c);
  *ecs_->enc_a = static_cast<CData>(a ? (*ecs_->enc_a | bit) : (*ecs_->enc_a & ~bit));
  *ecs_->enc_b = static_cast<CData>(b ? (*ecs_->enc_b | bit) : (*ecs_->enc_b & ~bit));
}

void RtlBench::QueueEncoderPeriod(std::size_t c, std::uint64_t start_clock,
                                  std::int32_t start_counts, std::uint32_t pulses,
                                  std::int32_t direction, std::uint32_t subticks,
                                  std::uint32_t divider) noexcept {
  if (!ecs_ || wired_) return;
  Feed& feed = feeds_[c];
  if (feed.count == kFeedQueue) {  // the oldest waiting period is dropped
    feed.head = (feed.head + 1) % kFeedQueue;
    --feed.count;
  }
  feed.queue[(feed.head + feed.count) % kFeedQueue] =
      FeedPeriod{start_clock, start_counts, pulses, direction, subticks == 0 ? 1 : subticks, divider};
  ++feed.count;
  feed_next_clock_ = std::min(feed_next_clock_, start_clock);
}

void RtlBench::SetLevels(std::size_t c, std::int64_t position) noexcept {
  const auto quarter = static_cast<unsigned>(position & 3);
  SetEncoderInput(c, quarter == 1 || quarter == 2, quarter >= 2);
}

void RtlBench::ServiceLineFeed() noexcept {
  // Levels set now are sampled by the ECS's input flops at the next rising edge.
  std::uint64_t next = UINT64_MAX;
  for (std::size_t c = 0; c < io::kChannels; ++c) {
    Feed& feed = feeds_[c];
    for (;;) {
      const FeedPeriod& p = feed.current;
      if (feed.active && feed.edges_done < p.pulses) {
        const std::uint64_t j = feed.edges_done + 1ULL;
        const std::uint64_t subtick = (j * p.subticks + p.pulses - 1) / p.pulses;
        const std::uint64_t at = p.start_clock + subtick * p.divider;
        if (at <= clocks_) {
          ++feed.edges_done;
          SetLevels(c, p.start_counts + p.direction * static_cast<std::int64_t>(feed.edges_done));
          continue;
        }
        next = std::min(next, at);
      }
      if (feed.count > 0) {
        const FeedPeriod& waiting = feed.queue[feed.head];
        if (waiting.start_clock <= clocks_) {
          feed.current = waiting;
          feed.head = (feed.head + 1) % kFeedQueue;
          --feed.count;
          feed.edges_done = 0;
          feed.active = true;
          SetLevels(c, feed.current.start_counts);
          continue;
        }
        next = std::min(next, waiting.start_clock);
      }
      break;
    }
  }
  feed_next_clock_ = next;
}

void RtlBench::SetPinInputs(Slot slot, std::uint8_t pins) noexcept {
  Board* board = slot == Slot::kTwin ? twin_.get() : ecs_.get();
  if (board != nullptr && !wired_) *board->pin_in = pins;
}

std::int64_t RtlBench::Origin() noexcept {
  if (!origin_set_) {
    origin_ps_ = (now_ps_ + kClockPs - 1) / kClockPs * kClockPs;
    origin_set_ = true;
  }
  return origin_ps_;
}

}  // namespace hiltwin::fpga_sim
