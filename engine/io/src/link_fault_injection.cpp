#include "hiltwin/io/link_fault_injection.h"

#include <stdexcept>

#include "hiltwin/kernel_glue/spec_items.h"

namespace hiltwin::io {
namespace {

using Kind = LinkFaultInjection::Kind;

struct KindName {
  Kind kind;
  std::string_view name;
};
constexpr std::array<KindName, 5> kKinds = {{{Kind::kCorruptRequest, "corrupt-request"},
                                              {Kind::kCorruptAnswer, "corrupt-answer"},
                                              {Kind::kDropAnswer, "drop-answer"},
                                              {Kind::kDelayAnswer, "delay-answer"},
                                              {Kind::kStuckEncoder, "stuck-encoder"}}};

constexpr const char* kForms =
    "accepted form: 'KIND,at=K[,count=N]' with KIND corrupt-request, corrupt-answer, "
    "drop-answer, delay-answer or stuck-encoder, e.g. 'drop-answer,at=4000,count=3'";

/// The board takes a frame count as 32 bits; a longer burst is a typo, not a plan.
constexpr std::uint64_t kMaxCount = 100'000'000;

[[noreturn]] void Fail(std::string_view spec, const std::string& what) {
  throw std::invalid_argument("'" + std::string(spec) + "': " + what + "; " + kForms);
}

std::string_view NameOf(Kind kind) noexcept {
  for (const KindName& k : kKinds) {
    if (k.kind == kind) return k.name;
  }
  return "?";
}

void SetKind(std::string_view spec, std::string_view item, LinkFaultInjection& injection) {
  for (const KindName& k : kKinds) {
    if (k.name == item) {
      injection.kind = k.kind;
      return;
    }
  }
  Fail(spec, "unknown fault kind '" + std::string(item) + "'");
}

std::uint64_t Whole(std::string_view spec, std::string_view key, std::string_view text) {
  return kernel_glue::spec_items::WholeOf(key, text, [&](const std::string& what) { Fail(spec, what); });
}

}  // namespace

LinkFaultInjection ParseLinkFaultInjection(std::string_view spec) {
  LinkFaultInjection injection;
  bool have_kind = false, have_at = false, have_count = false;
  std::size_t index = 0;
  kernel_glue::spec_items::ForEachItem(spec, [&](std::string_view item) {
    const std::size_t eq = item.find('=');
    if (index++ == 0) {
      if (eq != std::string_view::npos) Fail(spec, "the fault kind comes first");
      SetKind(spec, item, injection);
      have_kind = true;
      return;
    }
    if (eq == std::string_view::npos) Fail(spec, "'" + std::string(item) + "' is not key=value");
    const std::string_view key = item.substr(0, eq);
    const std::string_view value = item.substr(eq + 1);
    if (key == "at") {
      injection.first_exchange = Whole(spec, key, value);
      have_at = true;
    } else if (key == "count") {
      injection.count = Whole(spec, key, value);
      have_count = true;
    } else {
      Fail(spec, "unknown key '" + std::string(key) + "'");
    }
  });
  if (!have_kind) Fail(spec, "no fault kind given");
  if (!have_at) Fail(spec, "'at=' is required");
  if (injection.count == 0 || injection.count > kMaxCount) {
    Fail(spec, "count must be 1 .. " + std::to_string(kMaxCount));
  }
  injection.until_end = injection.kind == Kind::kStuckEncoder && !have_count;
  return injection;
}

std::string Describe(const LinkFaultInjection& injection) {
  std::string text = std::string(NameOf(injection.kind)) +
                     ",at=" + std::to_string(injection.first_exchange);
  if (!injection.until_end) text += ",count=" + std::to_string(injection.count);
  return text;
}

void LinkFaultSchedule::Add(const LinkFaultInjection& injection) {
  if (size_ == kMaxInjections) {
    throw std::length_error("at most " + std::to_string(kMaxInjections) + " link faults");
  }
  injections_[size_++] = injection;
}

void LinkFaultSchedule::CheckFiresWithin(std::uint64_t planned_exchanges) const {
  if (planned_exchanges == 0) return;
  for (const LinkFaultInjection& inj : injections()) {
    if (inj.first_exchange < planned_exchanges) continue;
    throw std::invalid_argument("'" + Describe(inj) + "' fires at exchange " +
                                std::to_string(inj.first_exchange) +
                                ", but the run's exchanges are 0 to " +
                                std::to_string(planned_exchanges - 1) +
                                "; choose an exchange inside the run or lengthen it");
  }
}

void LinkFaultSchedule::Arm(std::uint64_t exchange, FaultInjection& faults) const noexcept {
  for (const LinkFaultInjection& inj : injections()) {
    const auto count = static_cast<std::uint32_t>(inj.count);
    if (inj.kind == Kind::kStuckEncoder) {
      if (exchange == inj.first_exchange) faults.stick_encoder = true;
      if (!inj.until_end && exchange == inj.first_exchange + inj.count) {
        faults.stick_encoder = false;
      }
      continue;
    }
    if (exchange != inj.first_exchange) continue;
    switch (inj.kind) {
      case Kind::kCorruptRequest: faults.corrupt_requests += count; break;
      case Kind::kCorruptAnswer: faults.corrupt_answers += count; break;
      case Kind::kDropAnswer: faults.drop_answers += count; break;
      case Kind::kDelayAnswer: faults.delay_answers += count; break;
      case Kind::kStuckEncoder: break;
    }
  }
}

}  // namespace hiltwin::io
