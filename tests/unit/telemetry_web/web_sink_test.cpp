#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "hiltwin/telemetry/record_json.h"
#include "hiltwin/telemetry/sinks.h"

namespace hiltwin::telemetry {
namespace {

using std::chrono::milliseconds;
using std::chrono::steady_clock;

runtime::TelemetryRecord MakeRecord(double x_m) {
  runtime::TelemetryRecord r;
  r.ns = "twin";
  r.role = "twin";
  r.rate_hz = 1000.0;
  r.time_s = 1.25;
  r.cycle = 1250;
  r.cycles_planned = 5000;
  r.state = lifecycle::State::kRun;
  r.latency_p99_us = 12.5;
  r.latency_max_us = 30.0;
  r.latency_samples = 1000;
  r.distance_to_violation = 3;
  r.task.has_pose = true;
  r.task.x_m = x_m;
  r.task.y_m = -0.5;
  r.task.theta_rad = 0.75;
  r.task.joint_count = 2;
  r.task.joint_position_rad = {1.0, 2.0, 0.0, 0.0};
  r.task.joint_position_m = {0.1, 0.2, 0.0, 0.0};
  r.joint_names = {"wheel_left", "wheel_right"};
  return r;
}

/// The port of a sink made with port 0, from its start-up line "web page http://A:P/".
int PortOf(const runtime::TelemetrySink& sink) {
  const std::string text = sink.Describe();
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(R"(:(\d+)/$)"))) {
    throw std::runtime_error("no port in '" + text + "'");
  }
  return std::stoi(m[1].str());
}

/// An opened sink on a free port of 127.0.0.1, and a client for it.
struct Served {
  std::shared_ptr<runtime::TelemetrySink> sink = MakeWebSink({"127.0.0.1", 0});
  int port = PortOf(*sink);
  httplib::Client client{"127.0.0.1", port};

  Served() {
    sink->Open(runtime::TelemetryShape{}, "twin");
    client.set_connection_timeout(2, 0);
    client.set_read_timeout(5, 0);
  }
};

/// Reads /events until the first `data:` event and returns its JSON text ("" on failure).
std::string FirstEvent(httplib::Client& client, std::string* content_type = nullptr) {
  std::string received;
  std::string event;
  client.Get(
      "/events",
      [&](const httplib::Response& res) {
        if (content_type != nullptr) *content_type = res.get_header_value("Content-Type");
        return res.status == 200;
      },
      [&](const char* data, std::size_t length) {
        received.append(data, length);
        const std::size_t start = received.find("data: ");
        if (start == std::string::npos) return true;
        const std::size_t end = received.find("\n\n", start);
        if (end == std::string::npos) return true;
        event = received.substr(start + 6, end - start - 6);
        return false;  // one event is enough: close the stream
      });
  return event;
}

/// Polls `done` every 20 ms until it holds or 5 s pass.
bool WaitFor(const std::function<bool()>& done) {
  const auto give_up = steady_clock::now() + std::chrono::seconds(5);
  while (!done()) {
    if (steady_clock::now() >= give_up) return false;
    std::this_thread::sleep_for(milliseconds(20));
  }
  return true;
}

/// A raw TCP connection to 127.0.0.1:`port` (closed with the object). Non-blocking ones return
/// at once: a flood of them must not wait for a server that stops accepting.
class RawConnection {
 public:
  RawConnection(int port, bool nonblocking) : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
    if (fd_ < 0) throw std::runtime_error("no socket");
    if (nonblocking) fcntl(fd_, F_SETFL, fcntl(fd_, F_GETFL) | O_NONBLOCK);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 &&
        !(nonblocking && errno == EINPROGRESS)) {
      close(fd_);
      throw std::runtime_error("connect failed");
    }
  }
  ~RawConnection() {
    if (fd_ >= 0) close(fd_);
  }
  RawConnection(RawConnection&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  RawConnection& operator=(RawConnection&&) = delete;
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;
  [[nodiscard]] int fd() const noexcept { return fd_; }

 private:
  int fd_;
};

/// `count` open /events streams, each served (its first bytes read) before this returns.
std::vector<RawConnection> OpenStreams(int port, int count) {
  std::vector<RawConnection> streams;
  for (int i = 0; i < count; ++i) {
    RawConnection c(port, false);
    const std::string request = "GET /events HTTP/1.1\r\nHost: x\r\n\r\n";
    if (write(c.fd(), request.data(), request.size()) != static_cast<ssize_t>(request.size())) {
      throw std::runtime_error("write failed");
    }
    char buffer[64];
    if (read(c.fd(), buffer, sizeof(buffer)) <= 0) throw std::runtime_error("stream not served");
    streams.push_back(std::move(c));
  }
  return streams;
}

/// Connections that never send a request: nothing at all (a port scanner, a browser's spare
/// sockets), or only `first_bytes` of one. Opened five at a time, each five given up to 20 ms
/// to connect: a burst of SYNs beyond the listen backlog would be retried only a second later.
std::vector<RawConnection> OpenSilent(int port, int count, const std::string& first_bytes = "") {
  constexpr int kBatch = 5;
  std::vector<RawConnection> silent;
  silent.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; i += kBatch) {
    std::vector<pollfd> batch;
    for (int j = i; j < std::min(count, i + kBatch); ++j) {
      silent.emplace_back(port, true);
      batch.push_back({silent.back().fd(), POLLOUT, 0});
    }
    const auto give_up = steady_clock::now() + milliseconds(20);
    while (steady_clock::now() < give_up) {
      const bool all_in = std::all_of(batch.begin(), batch.end(),
                                      [](const pollfd& p) { return p.revents != 0; });
      if (all_in || poll(batch.data(), batch.size(), 1) < 0) break;
    }
    for (const pollfd& p : batch) {
      if ((p.revents & POLLOUT) != 0 && !first_bytes.empty()) {
        static_cast<void>(write(p.fd, first_bytes.data(), first_bytes.size()));
      }
    }
  }
  return silent;
}

/// How many sockets this process holds besides `clients` (the test's own ends): the server's
/// listening socket and every connection it has taken in.
int ServerSockets(const std::vector<RawConnection>& clients) {
  std::set<int> theirs;
  for (const RawConnection& c : clients) theirs.insert(c.fd());
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    const std::string target = std::filesystem::read_symlink(entry.path(), error).string();
    if (!error && target.starts_with("socket:") &&
        !theirs.contains(std::stoi(entry.path().filename().string()))) {
      ++count;
    }
  }
  return count;
}

TEST(WebSink, PageIsSelfContainedHtml) {
  Served served;
  const httplib::Result res = served.client.Get("/");
  ASSERT_TRUE(res) << httplib::to_string(res.error());
  EXPECT_EQ(res->status, 200);
  EXPECT_NE(res->get_header_value("Content-Type").find("text/html"), std::string::npos);
  EXPECT_NE(res->body.find("<svg id=\"arena\""), std::string::npos);
  EXPECT_NE(res->body.find("EventSource"), std::string::npos);
  // Nothing is fetched from elsewhere: no src/href/url()/@import that leaves the page.
  const std::regex external(
      R"((src|href)\s*=\s*["']?\s*(https?:)?//|url\(\s*["']?\s*(https?:)?//|@import)",
      std::regex::icase);
  EXPECT_FALSE(std::regex_search(res->body, external));
}

// The page's one script from outside the page is three.js, from this binary, at a relative
// address; it is libjs-three's file byte for byte (or, built without it, a 404 that says so),
// not compressed per request even when the browser accepts brotli or gzip: httplib's brotli
// of 0.85 MB took seconds on a loaded machine, and a short run ended before its page connected.
TEST(WebSink, ServesThreeJsFromTheBinary) {
  Served served;
  served.client.set_decompress(false);
  const httplib::Headers accept = {{"Accept-Encoding", "gzip, deflate, br"}};
  const httplib::Result page = served.client.Get("/");
  ASSERT_TRUE(page) << httplib::to_string(page.error());
  EXPECT_NE(page->body.find("<script src=\"three.min.js\"></script>"), std::string::npos);
  const httplib::Result res = served.client.Get("/three.min.js", accept);
  ASSERT_TRUE(res) << httplib::to_string(res.error());
#ifdef HILTWIN_THREE_JS
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Encoding"), "");
  EXPECT_EQ(res->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
  std::ifstream file(HILTWIN_THREE_JS, std::ios::binary);
  const std::string expected{std::istreambuf_iterator<char>(file), {}};
  ASSERT_GT(expected.size(), 100'000U) << HILTWIN_THREE_JS;
  EXPECT_TRUE(res->body == expected) << res->body.size() << " bytes, not the "
                                     << expected.size() << " of " << HILTWIN_THREE_JS;
#else
  EXPECT_EQ(res->status, 404);
  const httplib::Result plain = served.client.Get("/three.min.js");  // the message, uncompressed
  ASSERT_TRUE(plain) << httplib::to_string(plain.error());
  EXPECT_NE(plain->body.find("-DHILTWIN_WEB_3D=OFF"), std::string::npos) << plain->body;
#endif
}

TEST(WebSink, RecordIs503BeforeTheFirstAndTheLatestAfter) {
  Served served;
  httplib::Result before = served.client.Get("/record");
  ASSERT_TRUE(before);
  EXPECT_EQ(before->status, 503);
  EXPECT_TRUE(nlohmann::json::parse(before->body).contains("error"));

  served.sink->Publish(MakeRecord(0.5));
  served.sink->Publish(MakeRecord(1.5));
  httplib::Result after = served.client.Get("/record");
  ASSERT_TRUE(after);
  EXPECT_EQ(after->status, 200);
  EXPECT_EQ(nlohmann::json::parse(after->body),
            nlohmann::json::parse(ToJson(MakeRecord(1.5)).dump()));
}

TEST(WebSink, EventsStreamThePublishedRecord) {
  Served served;
  std::atomic<bool> publishing{true};
  std::thread publisher([&] {  // the telemetry thread: the client may connect before or after
    while (publishing) {
      served.sink->Publish(MakeRecord(0.25));
      std::this_thread::sleep_for(milliseconds(20));
    }
  });
  std::string content_type;
  const std::string event = FirstEvent(served.client, &content_type);
  publishing = false;
  publisher.join();
  EXPECT_EQ(content_type, "text/event-stream");
  ASSERT_FALSE(event.empty());
  EXPECT_EQ(event, ToJson(MakeRecord(0.25)).dump());
}

TEST(WebSink, AStreamOpenedAfterThePublishGetsTheLatestAtOnce) {
  Served served;
  served.sink->Publish(MakeRecord(2.0));  // a paused run publishes nothing new
  std::string received;
  served.client.Get("/events", [&](const char* data, std::size_t length) {
    received.append(data, length);
    return received.find("\n\n", received.find("data: ")) == std::string::npos;
  });
  EXPECT_NE(received.find("retry: "), std::string::npos);
  EXPECT_NE(received.find("data: " + ToJson(MakeRecord(2.0)).dump() + "\n\n"), std::string::npos);
}

TEST(WebSink, ASecondSinkOnTheSamePortNamesThePort) {
  Served served;
  const std::string port = std::to_string(served.port);
  try {
    auto second = MakeWebSink({"127.0.0.1", static_cast<std::uint16_t>(served.port)});
    FAIL() << "a second sink bound port " << port;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--web 127.0.0.1:" + port), std::string::npos) << what;
    EXPECT_NE(what.find("port " + port + " is already in use"), std::string::npos) << what;
    EXPECT_NE(what.find("pick another"), std::string::npos) << what;
  }
}

TEST(WebSink, APortHeldByAnotherProgramNamesThePort) {
  const int holder = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(holder, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(holder, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
  ASSERT_EQ(listen(holder, 1), 0);
  socklen_t length = sizeof(addr);
  ASSERT_EQ(getsockname(holder, reinterpret_cast<sockaddr*>(&addr), &length), 0);
  const std::uint16_t port = ntohs(addr.sin_port);
  EXPECT_THROW(
      {
        try {
          auto sink = MakeWebSink({"127.0.0.1", port});
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(
              std::string(e.what()).find("port " + std::to_string(port) + " is already in use"),
              std::string::npos)
              << e.what();
          throw;
        }
      },
      std::invalid_argument);
  close(holder);
}

TEST(WebSink, AnAddressOfAnotherMachineIsNamed) {
  // 192.0.2.1 is TEST-NET-1 (RFC 5737): never an address of this machine.
  try {
    auto sink = MakeWebSink({"192.0.2.1", 8080});
    FAIL() << "bound an address this machine does not have";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("192.0.2.1 is not an address of this machine"),
              std::string::npos)
        << e.what();
  }
}

TEST(WebSink, ASinkNeverOpenedFreesItsPort) {
  int port = 0;
  {
    auto sink = MakeWebSink({"127.0.0.1", 0});
    port = PortOf(*sink);
  }
  EXPECT_NO_THROW(auto again = MakeWebSink({"127.0.0.1", static_cast<std::uint16_t>(port)}));
}

TEST(WebSink, ASinkDestroyedRightAfterOpenEnds) {
  // httplib's stop() does nothing until its listener runs: the destructor must not miss it.
  for (int i = 0; i < 20; ++i) {
    auto sink = MakeWebSink({"127.0.0.1", 0});
    sink->Open(runtime::TelemetryShape{}, "twin");
  }
}

TEST(WebSink, DescribeGivesTheUrl) {
  Served served;
  EXPECT_EQ(served.sink->Describe(),
            "web page http://127.0.0.1:" + std::to_string(served.port) + "/");
}

TEST(WebSinkTiming, DestructionWithAnOpenStreamIsQuick) {
  auto served = std::make_unique<Served>();
  served->sink->Publish(MakeRecord(0.1));
  std::atomic<bool> streaming{false};
  std::thread browser([&] {  // a page that never closes its EventSource
    httplib::Client client("127.0.0.1", served->port);
    client.set_read_timeout(10, 0);
    client.Get("/events", [&](const char*, std::size_t) {
      streaming = true;
      return true;
    });
  });
  const auto give_up = steady_clock::now() + std::chrono::seconds(5);
  while (!streaming && steady_clock::now() < give_up) std::this_thread::sleep_for(milliseconds(5));
  ASSERT_TRUE(streaming);

  const auto start = steady_clock::now();
  served.reset();
  const auto took = steady_clock::now() - start;
  browser.join();  // its stream ended with the sink
  EXPECT_LT(took, std::chrono::seconds(1))
      << std::chrono::duration_cast<milliseconds>(took).count() << " ms";
}

TEST(WebSinkTiming, TheFinalRecordReachesAnOpenStreamBeforeItEnds) {
  auto served = std::make_unique<Served>();
  served->sink->Publish(MakeRecord(0.1));
  std::atomic<bool> streaming{false};
  std::string received;
  std::thread browser([&] {
    httplib::Client client("127.0.0.1", served->port);
    client.set_read_timeout(10, 0);
    client.Get("/events", [&](const char* data, std::size_t length) {
      received.append(data, length);
      if (received.find("data: ") != std::string::npos) streaming = true;
      return true;
    });
  });
  const auto give_up = steady_clock::now() + std::chrono::seconds(5);
  while (!streaming && steady_clock::now() < give_up) std::this_thread::sleep_for(milliseconds(5));
  ASSERT_TRUE(streaming);

  runtime::TelemetryRecord last = MakeRecord(9.0);
  last.final = true;
  served->sink->Publish(last);  // as RunSession does after the loop, just before the end
  served.reset();
  browser.join();
  EXPECT_NE(received.find("data: " + ToJson(last).dump() + "\n\n"), std::string::npos);
}

TEST(WebSinkTiming, PublishDoesNotWaitForAClientThatDoesNotRead) {
  Served served;
  // A raw client that asks for the stream and never reads: its socket buffers fill up.
  const int stalled = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(stalled, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(served.port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(connect(stalled, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
  const std::string request = "GET /events HTTP/1.1\r\nHost: x\r\n\r\n";
  ASSERT_EQ(write(stalled, request.data(), request.size()), static_cast<ssize_t>(request.size()));

  runtime::TelemetryRecord big = MakeRecord(0.0);
  big.ns = std::string(4000, 'n');  // about 4 kB a record: megabytes in all
  auto worst = steady_clock::duration::zero();
  for (int i = 0; i < 2000; ++i) {
    big.cycle = static_cast<std::uint64_t>(i);
    const auto start = steady_clock::now();
    served.sink->Publish(big);
    worst = std::max(worst, steady_clock::now() - start);
  }
  EXPECT_LT(worst, milliseconds(100));
  // Everyone else is still served.
  const httplib::Result res = served.client.Get("/record");
  ASSERT_TRUE(res);
  EXPECT_EQ(nlohmann::json::parse(res->body)["cycle"], 1999);
  close(stalled);
}

TEST(WebSink, StreamsBeyondTheLimitAreTurnedAway) {
  Served served;
  served.sink->Publish(MakeRecord(0.0));
  const std::vector<RawConnection> streams = OpenStreams(served.port, 6);  // the limit
  const httplib::Result seventh = served.client.Get("/events");
  ASSERT_TRUE(seventh);
  EXPECT_EQ(seventh->status, 503);
  EXPECT_NE(seventh->body.find("too many open pages"), std::string::npos);
  const httplib::Result record = served.client.Get("/record");  // workers left for the rest
  ASSERT_TRUE(record);
  EXPECT_EQ(record->status, 200);
}

// An EventSource treats any status but 200 as the end, for good: the page would show
// "connecting" forever. A page (Accept: text/event-stream) is told why, and when to retry.
TEST(WebSink, ASeventhPageIsToldWhyAndRetriesUntilASlotIsFree) {
  Served served;
  served.sink->Publish(MakeRecord(0.0));
  std::vector<RawConnection> streams = OpenStreams(served.port, 6);
  const httplib::Headers page{{"Accept", "text/event-stream"}};
  const httplib::Result seventh = served.client.Get("/events", page);
  ASSERT_TRUE(seventh) << httplib::to_string(seventh.error());
  EXPECT_EQ(seventh->status, 200);
  EXPECT_EQ(seventh->get_header_value("Content-Type"), "text/event-stream");
  EXPECT_NE(seventh->body.find("retry: 5000\n"), std::string::npos) << seventh->body;
  EXPECT_NE(seventh->body.find("event: busy\ndata: "), std::string::npos) << seventh->body;
  EXPECT_NE(seventh->body.find("6 pages already watch this run"), std::string::npos)
      << seventh->body;
  EXPECT_EQ(seventh->body.find("\ndata: {\"timestamp\""), std::string::npos) << "no record";

  streams.pop_back();  // one page closes: the next retry is served
  std::string received;
  httplib::Client retry("127.0.0.1", served.port);
  retry.set_read_timeout(5, 0);
  ASSERT_TRUE(WaitFor([&] {
    served.sink->Publish(MakeRecord(0.0));  // a write shows the closed page's stream is gone
    received.clear();
    retry.Get("/events", page, [&](const char* data, std::size_t length) {
      received.append(data, length);
      return received.find("\n\n", received.find("data: ")) == std::string::npos;
    });
    return received.find("data: " + ToJson(MakeRecord(0.0)).dump()) != std::string::npos;
  })) << received;
  EXPECT_EQ(received.find("event: busy"), std::string::npos) << received;
}

TEST(WebSink, DescribeNamesTheAddressItReallyBinds) {
  // "0" is 0.0.0.0 to the resolver: every interface, which the line must say.
  const auto any = MakeWebSink({"0", 0});
  const std::regex every(R"(web page http://0\.0\.0\.0:\d+/ \(every interface.*)");
  EXPECT_TRUE(std::regex_match(any->Describe(), every)) << any->Describe();
  const auto loopback = MakeWebSink({"127.1", 0});
  EXPECT_TRUE(std::regex_match(loopback->Describe(),
                               std::regex(R"(web page http://127\.0\.0\.1:\d+/)")))
      << loopback->Describe();
}

// 500 connections that never send a byte made /record wait over 40 s: each held one of the
// few workers for a whole keep-alive timeout, in turn. Now the kernel keeps them until their
// request arrives (TCP_DEFER_ACCEPT), one still silent after a second is dropped within about
// 10 ms, and six open pages leave eight workers to everything else.
TEST(WebSinkTiming, RecordAnswersWithinSecondsWhile500IdleConnectionsAreOpen) {
  Served served;
  served.sink->Publish(MakeRecord(0.5));
  const std::vector<RawConnection> streams = OpenStreams(served.port, 6);
  const std::vector<RawConnection> idle = OpenSilent(served.port, 500);
  httplib::Client client("127.0.0.1", served.port);
  client.set_connection_timeout(15, 0);
  client.set_read_timeout(15, 0);
  const auto start = steady_clock::now();
  const httplib::Result res = client.Get("/record");
  const auto took = steady_clock::now() - start;
  ASSERT_TRUE(res) << httplib::to_string(res.error());
  EXPECT_EQ(res->status, 200);
  EXPECT_LT(took, std::chrono::seconds(5))
      << std::chrono::duration_cast<milliseconds>(took).count() << " ms";
}

// Connections that start a request and stall are handed over at once, and each holds a worker
// up to the read timeout: they pile up in the queue, never beyond the cap. Before the cap
// every one of them held a descriptor (a process out of descriptors cannot write its report).
TEST(WebSinkTiming, AtMost128ConnectionsAreTakenInAtOnce) {
  Served served;
  const int before = ServerSockets({});
  const std::vector<RawConnection> stalled = OpenSilent(served.port, 500, "GET /rec");
  int most = 0;
  const auto until = steady_clock::now() + milliseconds(500);
  while (steady_clock::now() < until) {
    most = std::max(most, ServerSockets(stalled) - before);
    std::this_thread::sleep_for(milliseconds(5));
  }
  EXPECT_GT(most, 100) << "the flood was not taken in up to the cap";
  EXPECT_LE(most, 128 + 1);  // and the one the accept loop has taken and waits to queue
}

}  // namespace
}  // namespace hiltwin::telemetry
