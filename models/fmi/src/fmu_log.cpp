// The log ring: vsnprintf into a slot on the producer side; strings and I/O only in Drain().
#include "fmu_log.h"

#include <cstdio>
#include <cstring>
#include <utility>

namespace hiltwin::fmi {

const char* StatusName(fmi2Status status) noexcept {
  switch (status) {
    case fmi2OK:
      return "fmi2OK";
    case fmi2Warning:
      return "fmi2Warning";
    case fmi2Discard:
      return "fmi2Discard";
    case fmi2Error:
      return "fmi2Error";
    case fmi2Fatal:
      return "fmi2Fatal";
    case fmi2Pending:
      return "fmi2Pending";
  }
  return "an unknown fmi2Status";
}

FmuLog::FmuLog(std::string instance_name, std::size_t capacity_messages, Sink sink)
    : instance_name_(std::move(instance_name)),
      capacity_(capacity_messages > 0 ? capacity_messages : 1),
      slots_(std::make_unique<Slot[]>(capacity_)),
      sink_(std::move(sink)) {
  if (!sink_) {
    sink_ = [](std::string_view line) {
      std::fprintf(stderr, "%.*s\n", static_cast<int>(line.size()), line.data());
    };
  }
}

void FmuLog::Callback(fmi2ComponentEnvironment environment, fmi2String /*instance_name*/,
                      fmi2Status status, fmi2String category, fmi2String message, ...) noexcept {
  // The FMU's instance name is ours (we passed it to fmi2Instantiate), so it is not copied.
  auto* log = static_cast<FmuLog*>(environment);
  if (log == nullptr || message == nullptr) {
    return;
  }
  std::va_list args;
  va_start(args, message);
  log->Push(status, category, message, args);
  va_end(args);
}

void FmuLog::Push(fmi2Status status, const char* category, const char* format,
                  std::va_list args) noexcept {
  const std::uint64_t written = written_.load(std::memory_order_relaxed);
  if (written - read_.load(std::memory_order_acquire) >= capacity_) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  Slot& slot = slots_[written % capacity_];
  slot.status = status;
  std::snprintf(slot.category, sizeof slot.category, "%s", category != nullptr ? category : "");
  // The format comes from the FMU, as the FMI logger's contract has it.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
  const int length = std::vsnprintf(slot.text, sizeof slot.text, format, args);
#pragma GCC diagnostic pop
  if (length >= static_cast<int>(sizeof slot.text)) {
    std::memcpy(slot.text + sizeof slot.text - 4, "...", 4);
  } else if (length < 0) {
    std::snprintf(slot.text, sizeof slot.text, "(unformattable message: %s)", format);
  }
  written_.store(written + 1, std::memory_order_release);
}

std::string FmuLog::Format(const Slot& slot) const {
  std::string line = "fmu " + instance_name_ + " [" + StatusName(slot.status) + "]";
  if (slot.category[0] != '\0') {
    line += std::string(" ") + slot.category;
  }
  return line + ": " + slot.text;
}

std::size_t FmuLog::Drain() {
  const std::lock_guard lock(drain_mutex_);
  std::uint64_t read = read_.load(std::memory_order_relaxed);
  const std::uint64_t written = written_.load(std::memory_order_acquire);
  std::size_t count = 0;
  for (; read != written; ++read, ++count) {
    const std::string line = Format(slots_[read % capacity_]);
    read_.store(read + 1, std::memory_order_release);  // the slot is copied: free it
    sink_(line);
  }
  const std::uint64_t dropped = dropped_.load(std::memory_order_relaxed);
  if (dropped != dropped_reported_) {
    sink_("fmu " + instance_name_ + ": " + std::to_string(dropped - dropped_reported_) +
          " log messages dropped (the ring holds " + std::to_string(capacity_) +
          "; it is drained at Start, Reset and Finish): log less from fmi2DoStep");
    dropped_reported_ = dropped;
  }
  return count;
}

}  // namespace hiltwin::fmi
