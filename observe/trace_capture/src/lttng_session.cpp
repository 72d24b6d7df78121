// One LTTng recording session of the hiltwin provider, through liblttng-ctl: create, one
// user-space channel, the events, contexts, start; stop, figures, destroy.
#include "hiltwin/trace_capture/lttng_session.h"

#include <spdlog/spdlog.h>

#include "hiltwin/trace_capture/capture_error.h"

#if HILTWIN_WITH_LTTNG

#include <lttng/lttng.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <memory>
#include <thread>

#include "lttng_text.h"
#include "session_daemon.h"

namespace hiltwin::trace_capture {
namespace {

namespace fs = std::filesystem;

constexpr const char* kChannel = "hiltwin";
constexpr const char* kEvents = "hiltwin:*";
// Upper bounds, never expected: the consumer flushes what is left in a few hundred ms.
constexpr std::chrono::milliseconds kDataTimeout{30'000};
constexpr int kDestroyTimeoutMs = 30'000;
constexpr std::chrono::milliseconds kPollTick{20};

std::string NextSessionName() {
  static std::atomic<unsigned> counter{0};
  return "hiltwin-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

std::string Hint(int code) {
  if (code == -LTTNG_ERR_EPERM || code == -LTTNG_ERR_NO_SESSIOND) {
    return ": run as root, or join the `tracing` group";
  }
  return "";
}

int Check(int code, const std::string& what) {
  if (code < 0) throw CaptureError("LTTng: " + what + ": " + LttngText(code) + Hint(code));
  return code;
}

lttng_domain UserSpace() {
  lttng_domain domain{};
  domain.type = LTTNG_DOMAIN_UST;
  // Per-user buffers outlive the traced process, so a run that ends before Stop() loses
  // nothing, and the daemon reports their discarded events (per-PID buffers go with the app).
  domain.buf_type = LTTNG_BUFFER_PER_UID;
  return domain;
}

// A liblttng-ctl handle on the session's user-space domain.
class Handle {
 public:
  explicit Handle(const std::string& session) {
    lttng_domain domain = UserSpace();
    handle_ = lttng_create_handle(session.c_str(), &domain);
    if (handle_ == nullptr) throw CaptureError("LTTng: no handle for session " + session);
  }
  ~Handle() { lttng_destroy_handle(handle_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  [[nodiscard]] lttng_handle* get() const noexcept { return handle_; }

 private:
  lttng_handle* handle_ = nullptr;
};

// Whether process `pid` has registered with the daemon: the daemon lists the tracepoints of
// registered applications only, each with its pid.
bool Registered(int pid) {
  lttng_domain domain = UserSpace();
  const std::unique_ptr<lttng_handle, decltype(&lttng_destroy_handle)> handle(
      lttng_create_handle(nullptr, &domain), &lttng_destroy_handle);
  if (!handle) throw CaptureError("LTTng: no handle for listing tracepoints");
  lttng_event* events = nullptr;
  const int count = Check(lttng_list_tracepoints(handle.get(), &events), "listing tracepoints");
  const std::unique_ptr<lttng_event, decltype(&std::free)> owned(events, &std::free);
  for (int i = 0; i < count; ++i) {
    if (events[i].pid == pid) return true;
  }
  return false;
}

void AwaitRegistration(int pid, int timeout_ms) {
  if (Registered(pid)) return;
  spdlog::info("waiting for process {} to register with the LTTng session daemon", pid);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!Registered(pid)) {
    if (std::chrono::steady_clock::now() >= deadline) {
      throw CaptureError("LTTng: process " + std::to_string(pid) +
                         " did not register with the session daemon within " +
                         std::to_string(timeout_ms) +
                         " ms, so its events could not be recorded; is the daemon one it may "
                         "reach (its own user's, or root's)?");
    }
    std::this_thread::sleep_for(kPollTick);
  }
}

void CreateSession(const std::string& name, const std::string& output_dir) {
  // The daemon writes the trace, from its own working directory: give it an absolute path.
  const fs::path dir = fs::absolute(output_dir);
  fs::create_directories(dir);
  lttng_session_descriptor* descriptor =
      lttng_session_descriptor_local_create(name.c_str(), dir.c_str());
  if (descriptor == nullptr) throw CaptureError("LTTng: bad session output " + dir.string());
  const lttng_error_code code = lttng_create_session_ext(descriptor);
  lttng_session_descriptor_destroy(descriptor);
  if (code != LTTNG_OK) {
    throw CaptureError("LTTng: creating session " + name + " writing to " + dir.string() + ": " +
                       LttngText(code) + Hint(-code));
  }
}

void EnableChannel(const Handle& handle, const LttngChannelSize& size) {
  lttng_domain domain = UserSpace();
  const std::unique_ptr<lttng_channel, decltype(&lttng_channel_destroy)> channel(
      lttng_channel_create(&domain), &lttng_channel_destroy);
  if (!channel) throw CaptureError("LTTng: cannot allocate a channel");
  std::strncpy(channel->name, kChannel, sizeof channel->name - 1);
  channel->attr.overwrite = 0;  // discard when full: the loop never waits for the consumer
  channel->attr.subbuf_size = size.subbuf_bytes;
  channel->attr.num_subbuf = size.subbuf_count;
  channel->attr.switch_timer_interval = size.switch_timer_us;
  Check(lttng_channel_set_blocking_timeout(channel.get(), 0), "channel blocking timeout");
  Check(lttng_enable_channel(handle.get(), channel.get()), "enabling channel hiltwin");
}

// The events, with one context: vpid, by which the trace's reader picks one process's run out
// of several (ReadCtfTrace). Not vtid, which nothing reads (loop_start names the loop thread):
// it cost the tracing thread 130 of an event's 1,695 instructions (callgrind,
// bench/trace), and 4 bytes.
void EnableEventsAndContext(const Handle& handle) {
  const std::unique_ptr<lttng_event, decltype(&lttng_event_destroy)> event(lttng_event_create(),
                                                                           &lttng_event_destroy);
  if (!event) throw CaptureError("LTTng: cannot allocate an event");
  std::strncpy(event->name, kEvents, sizeof event->name - 1);
  event->type = LTTNG_EVENT_TRACEPOINT;
  event->loglevel_type = LTTNG_EVENT_LOGLEVEL_ALL;
  Check(
      lttng_enable_event_with_exclusions(handle.get(), event.get(), kChannel, nullptr, 0, nullptr),
      "enabling events hiltwin:*");
  lttng_event_context context{};
  context.ctx = LTTNG_EVENT_CONTEXT_VPID;
  Check(lttng_add_context(handle.get(), &context, nullptr, kChannel), "adding the vpid context");
}

/// The session's user-space process tracker: only `pid`'s events are recorded.
void TrackOnly(const std::string& session, int pid) {
  lttng_process_attr_tracker_handle* tracker = nullptr;
  Check(lttng_session_get_tracker_handle(session.c_str(), LTTNG_DOMAIN_UST,
                                         LTTNG_PROCESS_ATTR_VIRTUAL_PROCESS_ID, &tracker),
        "getting the process tracker");
  const std::unique_ptr<lttng_process_attr_tracker_handle,
                        decltype(&lttng_process_attr_tracker_handle_destroy)>
      owned(tracker, &lttng_process_attr_tracker_handle_destroy);
  if (lttng_process_attr_tracker_handle_set_tracking_policy(tracker,
                                                            LTTNG_TRACKING_POLICY_INCLUDE_SET) !=
          LTTNG_PROCESS_ATTR_TRACKER_HANDLE_STATUS_OK ||
      lttng_process_attr_virtual_process_id_tracker_handle_add_pid(tracker, pid) !=
          LTTNG_PROCESS_ATTR_TRACKER_HANDLE_STATUS_OK) {
    throw CaptureError("LTTng: cannot restrict session " + session + " to process " +
                       std::to_string(pid));
  }
}

// lttng_stop_tracing() waits for the consumer the same way, but without a bound.
void StopAndWaitForData(const std::string& name) {
  Check(lttng_stop_tracing_no_wait(name.c_str()), "stopping session " + name);
  const auto deadline = std::chrono::steady_clock::now() + kDataTimeout;
  while (Check(lttng_data_pending(name.c_str()), "waiting for the trace data") != 0) {
    if (std::chrono::steady_clock::now() >= deadline) {
      throw CaptureError("LTTng: the consumer had not written session " + name + "'s data " +
                         "after " + std::to_string(kDataTimeout.count()) +
                         " ms: the trace may be incomplete");
    }
    std::this_thread::sleep_for(kPollTick);
  }
}

// The daemon counts what its buffers dropped, for per-user buffers too (it asks the consumer).
// In discard mode a full buffer drops events (discarded_events) and never whole packets, so
// lost_packets stays 0 here; the CTF reader also counts discarded events from the packets.
void ReadChannelFigures(const std::string& name, LttngChannelFigures& figures) {
  const Handle handle(name);
  lttng_channel* channels = nullptr;
  const int count = Check(lttng_list_channels(handle.get(), &channels), "listing channels");
  const std::unique_ptr<lttng_channel, decltype(&std::free)> owned(channels, &std::free);
  for (int i = 0; i < count; ++i) {
    lttng_channel* channel = &channels[i];
    if (std::strcmp(channel->name, kChannel) != 0) continue;
    Check(lttng_channel_get_discarded_event_count(channel, &figures.discarded_events),
          "reading the discarded-event count");
    Check(lttng_channel_get_lost_packet_count(channel, &figures.lost_packets),
          "reading the lost-packet count");
    return;
  }
  throw CaptureError("LTTng: session " + name + " has no channel " + kChannel);
}

void DestroySession(const std::string& name) {
  lttng_destruction_handle* handle = nullptr;
  const lttng_error_code code = lttng_destroy_session_ext(name.c_str(), &handle);
  if (code != LTTNG_OK) {
    throw CaptureError("LTTng: destroying session " + name + ": " + LttngText(code));
  }
  const std::unique_ptr<lttng_destruction_handle, decltype(&lttng_destruction_handle_destroy)>
      owned(handle, &lttng_destruction_handle_destroy);
  const auto waited = lttng_destruction_handle_wait_for_completion(handle, kDestroyTimeoutMs);
  if (waited != LTTNG_DESTRUCTION_HANDLE_STATUS_COMPLETED) {
    throw CaptureError("LTTng: session " + name + " was not destroyed within " +
                       std::to_string(kDestroyTimeoutMs) + " ms");
  }
  lttng_error_code result = LTTNG_OK;
  if (lttng_destruction_handle_get_result(handle, &result) == LTTNG_DESTRUCTION_HANDLE_STATUS_OK &&
      result != LTTNG_OK) {
    throw CaptureError("LTTng: destroying session " + name + ": " + LttngText(result));
  }
}

// Cleans up after a failed start; the first error is the one worth reporting.
void DestroyQuietly(const std::string& name) noexcept {
  try {
    DestroySession(name);
  } catch (const std::exception& error) {
    spdlog::warn("{}", error.what());
  }
}

}  // namespace

LttngSession::LttngSession(const LttngSessionConfig& config)
    : daemon_(SessionDaemon::Ensure(config.may_start_daemon)), name_(NextSessionName()) {
  const LttngChannelSize size = ChannelSizeFor(config.rate_hz);
  figures_.subbuf_bytes = size.subbuf_bytes;
  figures_.subbuf_count = size.subbuf_count;
  if (config.only_pid > 0 && config.await_registration) {
    AwaitRegistration(config.only_pid, config.registration_timeout_ms);
  }
  CreateSession(name_, config.output_dir);
  try {
    const Handle handle(name_);
    EnableChannel(handle, size);
    EnableEventsAndContext(handle);
    if (config.only_pid > 0) TrackOnly(name_, config.only_pid);
    Check(lttng_start_tracing(name_.c_str()), "starting session " + name_);
  } catch (...) {
    DestroyQuietly(name_);
    throw;  // daemon_ goes with this object: a daemon started for it stops
  }
}

LttngSession::~LttngSession() {
  try {
    Stop();
  } catch (const std::exception& error) {
    spdlog::warn("LTTng session {}: {}", name_, error.what());
  }
  // daemon_ is released after this body, so the daemon outlives the session's destruction.
}

LttngChannelFigures LttngSession::Stop() {
  if (stopped_) return figures_;
  stopped_ = true;  // whatever fails below, the session is destroyed once
  std::exception_ptr error;
  try {
    StopAndWaitForData(name_);
    ReadChannelFigures(name_, figures_);
  } catch (...) {
    error = std::current_exception();
  }
  try {
    DestroySession(name_);
  } catch (...) {
    if (!error) error = std::current_exception();
  }
  if (error) std::rethrow_exception(error);
  return figures_;
}

int LttngSession::daemon_pid() const noexcept { return daemon_ ? daemon_->pid() : 0; }

}  // namespace hiltwin::trace_capture

#else  // !HILTWIN_WITH_LTTNG

namespace hiltwin::trace_capture {

LttngSession::LttngSession(const LttngSessionConfig& /*config*/) {
  throw CaptureError(
      "this hiltwin was built without LTTng (HILTWIN_WITH_LTTNG=OFF): record a timing log with "
      "`hiltwin run --timing-log FILE` and analyse it with `hiltwin trace --analyze FILE`");
}

LttngSession::~LttngSession() = default;

LttngChannelFigures LttngSession::Stop() { return figures_; }

int LttngSession::daemon_pid() const noexcept { return 0; }

}  // namespace hiltwin::trace_capture

#endif  // HILTWIN_WITH_LTTNG
