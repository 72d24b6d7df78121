#include "hiltwin/runtime/overrun_injection.h"

#include <stdexcept>

#include "hiltwin/kernel_glue/spec_items.h"

namespace hiltwin::runtime {
namespace {

constexpr const char* kOverrunForms =
    "accepted forms: 'at=K[,count=N],extra-us=US' or 'every=P[,offset=O],extra-us=US', "
    "e.g. 'at=40000,count=5,extra-us=600' or 'every=1000,extra-us=300'";

[[noreturn]] void FailOverrun(std::string_view spec, const std::string& what) {
  throw std::invalid_argument("'" + std::string(spec) + "': " + what + "; " + kOverrunForms);
}

std::uint64_t ParseCount(std::string_view spec, std::string_view key, std::string_view text) {
  return kernel_glue::spec_items::WholeOf(key, text, [&](const std::string& what) { FailOverrun(spec, what); });
}

}  // namespace

OverrunInjection ParseOverrunInjection(std::string_view spec) {
  OverrunInjection injection;
  bool have_at = false, have_every = false, have_extra = false, have_count = false,
       have_offset = false;
  kernel_glue::spec_items::ForEachItem(spec, [&](std::string_view item) {
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) FailOverrun(spec, "'" + std::string(item) + "' is not key=value");
    const std::string_view key = item.substr(0, eq);
    const std::string_view value = item.substr(eq + 1);
    if (key == "at") {
      injection.first_cycle = ParseCount(spec, key, value);
      have_at = true;
    } else if (key == "count") {
      injection.count = ParseCount(spec, key, value);
      have_count = true;
    } else if (key == "every") {
      injection.every = ParseCount(spec, key, value);
      have_every = true;
    } else if (key == "offset") {
      injection.offset = ParseCount(spec, key, value);
      have_offset = true;
    } else if (key == "extra-us") {
      const std::uint64_t extra_us = ParseCount(spec, key, value);
      if (extra_us == 0 || extra_us > 10'000'000) FailOverrun(spec, "extra-us must be 1 .. 10000000 µs");
      injection.extra_ns = static_cast<kernel_glue::TimeNs>(extra_us) * kernel_glue::kNsPerUs;
      have_extra = true;
    } else {
      FailOverrun(spec, "unknown key '" + std::string(key) + "'");
    }
  });
  if (have_at == have_every) FailOverrun(spec, "give exactly one of 'at=' and 'every='");
  if (!have_extra) FailOverrun(spec, "'extra-us=' is required");
  if (have_at && have_offset) FailOverrun(spec, "'offset=' goes with 'every='");
  if (have_every && have_count) FailOverrun(spec, "'count=' goes with 'at='");
  if (have_at && injection.count == 0) FailOverrun(spec, "count must be at least 1");
  if (have_every) {
    if (injection.every == 0) FailOverrun(spec, "every must be at least 1");
    if (injection.offset >= injection.every) FailOverrun(spec, "offset must be less than every");
    injection.kind = OverrunInjection::Kind::kEvery;
  }
  return injection;
}

void OverrunInjector::Add(const OverrunInjection& injection) {
  if (size_ == kMaxInjections) {
    throw std::length_error("at most " + std::to_string(kMaxInjections) + " overrun injections");
  }
  injections_[size_++] = injection;
}

std::string Describe(const OverrunInjection& injection) {
  std::string text = injection.kind == OverrunInjection::Kind::kAt
                         ? "at=" + std::to_string(injection.first_cycle) +
                               ",count=" + std::to_string(injection.count)
                         : "every=" + std::to_string(injection.every) +
                               ",offset=" + std::to_string(injection.offset);
  return text + ",extra-us=" + std::to_string(injection.extra_ns / kernel_glue::kNsPerUs);
}

void OverrunInjector::CheckFiresWithin(std::uint64_t planned_cycles) const {
  if (planned_cycles == 0) return;  // runs until stopped: every cycle may come
  for (std::size_t i = 0; i < size_; ++i) {
    const OverrunInjection& inj = injections_[i];
    const std::uint64_t first =
        inj.kind == OverrunInjection::Kind::kAt ? inj.first_cycle : inj.offset;
    if (first < planned_cycles) continue;
    throw std::invalid_argument("'" + Describe(inj) + "' first fires at cycle " +
                                std::to_string(first) + ", but the run's cycles are 0 to " +
                                std::to_string(planned_cycles - 1) +
                                "; choose a cycle inside the run or lengthen it");
  }
}

kernel_glue::TimeNs OverrunInjector::ExtraNs(std::uint64_t cycle) const noexcept {
  kernel_glue::TimeNs extra_ns = 0;
  for (std::size_t i = 0; i < size_; ++i) {
    const OverrunInjection& inj = injections_[i];
    const bool hit = inj.kind == OverrunInjection::Kind::kAt
                         ? cycle >= inj.first_cycle && cycle - inj.first_cycle < inj.count
                         : cycle % inj.every == inj.offset;
    if (hit) extra_ns += inj.extra_ns;
  }
  return extra_ns;
}

}  // namespace hiltwin::runtime
