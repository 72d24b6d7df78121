#include "hiltwin/io/encoder_lines.h"

#include <algorithm>

namespace hiltwin::io {

void EncoderLineHistory::OnPeriod(const std::array<PulseSegment, kChannels>& channels) noexcept {
  ++newest_;
  EncoderPeriod& slot = ring_[newest_ % kEncoderLineHistory];
  slot.index = newest_;
  slot.channels = channels;
}

LineView EncoderLineHistory::Lines(std::int64_t /*t_ns*/) noexcept {
  LineView view;
  view.newest = newest_;
  return view;
}

bool EncoderLineHistory::Period(std::uint64_t index, EncoderPeriod& out) noexcept {
  if (index == 0 || index > newest_ || newest_ - index >= kEncoderLineHistory) return false;
  out = ring_[index % kEncoderLineHistory];
  return true;
}

void EncoderLineReader::Update(EncoderLineSource& source, std::int64_t t_ns, bool stuck) noexcept {
  const LineView view = source.Lines(t_ns);
  const std::int64_t until = std::min(t_ns, view.known_until_ns);
  if (view.newest == 0) return;  // the emulator has not run: the lines rest where they are
  if (current_.index == 0) {
    if (!source.Period(view.newest, next_)) return;
    current_ = next_;
    JumpTo(until, /*load=*/true, stuck);
  }
  while (current_.index < view.newest) {
    if (!source.Period(current_.index + 1, next_)) {
      // Overwritten before this reader got to it: its edges are gone. Continue from the newest.
      if (!source.Period(view.newest, next_)) return;
      current_ = next_;
      JumpTo(until, /*load=*/false, stuck);
      ++resyncs_;
      break;
    }
    // The next sampling moment cancels the current period's edges after it (the emulator
    // starts the next period from the position reached by then).
    ReplayCurrent(std::min(until, next_.start_ns()), stuck);
    if (next_.start_ns() > until) break;  // that period starts after this read
    current_ = next_;
    edges_done_.fill(0);
    bool continuous = true;
    for (std::size_t c = 0; c < kChannels; ++c) {
      continuous = continuous && WrapToRelative(line_pos_[c]) == current_.channels[c].start_counts;
    }
    if (!continuous) {  // the twin restarted (INIT puts its emulator at 0)
      JumpTo(current_.start_ns(), /*load=*/false, stuck);
      ++resyncs_;
    }
  }
  ReplayCurrent(until, stuck);
}

void EncoderLineReader::ReplayCurrent(std::int64_t until_ns, bool stuck) noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const PulseSegment& segment = current_.channels[c];
    std::uint32_t done = edges_done_[c];
    while (done < segment.pulses) {
      const std::int64_t edge_ns = segment.EdgeTimeNs(done + 1);
      if (edge_ns > until_ns) break;
      ++done;
      line_pos_[c] += segment.direction;
      if (!stuck) readers_[c].OnLevels(LevelsAt(line_pos_[c]), edge_ns);
    }
    edges_ += done - edges_done_[c];
    edges_done_[c] = done;
  }
}

void EncoderLineReader::JumpTo(std::int64_t t_ns, bool load, bool stuck) noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const PulseSegment& segment = current_.channels[c];
    edges_done_[c] = segment.EdgesBy(t_ns);
    const std::int32_t position = segment.PositionAt(t_ns);
    if (load) {
      line_pos_[c] = position;
      readers_[c].Resync(LevelsAt(position), position);
      continue;
    }
    // The nearest unwrapped position with that 14-bit value; the reader's count moves with it.
    const std::int32_t delta = WrapToRelative(std::int64_t{position} - line_pos_[c]);
    line_pos_[c] += delta;
    if (!stuck && delta != 0) {
      readers_[c].Resync(LevelsAt(line_pos_[c]), readers_[c].counts() + delta);
    }
  }
}

EncoderLineCounters EncoderLineReader::counters() const noexcept {
  EncoderLineCounters counters;
  counters.edges = edges_;
  counters.resyncs = resyncs_;
  for (const QuadratureReader& reader : readers_) {
    counters.illegal_transitions += reader.illegal_transitions();
    counters.too_fast_edges += reader.too_fast();
  }
  return counters;
}

}  // namespace hiltwin::io
