#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <stdexcept>
#include <string>
#include <thread>

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
  std::vector<int> streams;
  for (int i = 0; i < 6; ++i) {  // the limit: six pages at once
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(served.port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)), 0);
    const std::string request = "GET /events HTTP/1.1\r\nHost: x\r\n\r\n";
    ASSERT_GT(write(fd, request.data(), request.size()), 0);
    char buffer[64];
    ASSERT_GT(read(fd, buffer, sizeof(buffer)), 0);  // served: its worker holds the stream
    streams.push_back(fd);
  }
  const httplib::Result seventh = served.client.Get("/events");
  ASSERT_TRUE(seventh);
  EXPECT_EQ(seventh->status, 503);
  EXPECT_NE(seventh->body.find("too many open pages"), std::string::npos);
  const httplib::Result record = served.client.Get("/record");  // workers left for the rest
  ASSERT_TRUE(record);
  EXPECT_EQ(record->status, 200);
  for (const int fd : streams) close(fd);
}

}  // namespace
}  // namespace hiltwin::telemetry
