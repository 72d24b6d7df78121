// `hiltwin run --web` as a user's browser sees it. Headless Chromium loads the page from a
// running twin and prints its DOM (--dump-dom); the page keeps every streamed value in the DOM
// (#arena data-samples, #robot data-x/y/theta and transform, #trail points, #t-* cells), so
// the dump shows whether the robot was drawn from the stream.
//
// When --dump-dom dumps (Chromium 156, new headless mode, measured with a never-ending
// text/event-stream):
//  - alone, or with --timeout=N: right after the load event, before the EventSource has
//    delivered anything (data-samples="0"). --timeout only cuts a page whose load event has
//    not fired yet; an open EventSource does not hold the load event.
//  - with --virtual-time-budget=N: not until the stream has ended. Virtual time stays paused
//    while a fetch is pending, and the EventSource's is pending for as long as the stream
//    lasts, so against a stream that never ends Chromium never exits (--timeout does not
//    help then either). Events are still delivered and handled while virtual time is paused.
// So the test lets the twin end: the page closes its EventSource on the final record (or
// the server goes away), the budget runs out in virtual time at once, and the DOM is dumped
// with every record the page received. test::Run's timeout guards a hang.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"

namespace hiltwin {
namespace {

namespace fs = std::filesystem;
constexpr const char* kChromium = "/usr/bin/chromium";

fs::path TempDir(const char* name) {
  fs::path dir = fs::temp_directory_path() /
                 ("hiltwin-web-" + std::string(name) + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// A TCP socket on 127.0.0.1 with a port the kernel chose; `listening` keeps the port taken.
class LoopbackSocket {
 public:
  explicit LoopbackSocket(bool listening) : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof(addr);
    if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
        (listening && listen(fd_, 1) != 0) ||
        getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &length) != 0) {
      throw std::runtime_error("no loopback socket");
    }
    port_ = ntohs(addr.sin_port);
  }
  ~LoopbackSocket() { close(fd_); }
  LoopbackSocket(const LoopbackSocket&) = delete;
  LoopbackSocket& operator=(const LoopbackSocket&) = delete;
  [[nodiscard]] int port() const noexcept { return port_; }

 private:
  int fd_;
  int port_ = 0;
};

/// A port free now (parallel tests each get their own; the kernel does not hand it out again
/// at once).
int FreePort() { return LoopbackSocket(false).port(); }

/// Waits until the twin's web server answers (any status: 503 before the first record).
bool WaitUntilServing(int port, std::chrono::seconds timeout) {
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  httplib::Client client("127.0.0.1", port);
  client.set_connection_timeout(0, 200'000);
  while (std::chrono::steady_clock::now() < give_up) {
    if (client.Get("/record")) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

/// Every record of /events until the final one or the end of the stream.
std::vector<nlohmann::json> ReadEvents(int port) {
  std::vector<nlohmann::json> records;
  std::string buffer;
  httplib::Client client("127.0.0.1", port);
  client.set_read_timeout(30, 0);
  client.Get("/events", [&](const char* data, std::size_t length) {
    buffer.append(data, length);
    for (std::size_t end = buffer.find("\n\n"); end != std::string::npos;
         end = buffer.find("\n\n")) {
      const std::string event = buffer.substr(0, end);
      buffer.erase(0, end + 2);
      if (event.rfind("data: ", 0) == 0) records.push_back(nlohmann::json::parse(event.substr(6)));
    }
    return records.empty() || !records.back()["final"].get<bool>();
  });
  return records;
}

/// The opening tag of the element with this id in a dumped DOM ("" when absent).
std::string Tag(const std::string& dom, const std::string& id) {
  std::smatch m;
  const std::regex tag("<[a-z]+ [^>]*id=\"" + id + "\"[^>]*>");
  return std::regex_search(dom, m, tag) ? m[0].str() : "";
}

std::string Attribute(const std::string& tag, const std::string& name) {
  std::smatch m;
  const std::regex attribute(" " + name + "=\"([^\"]*)\"");
  return std::regex_search(tag, m, attribute) ? m[1].str() : "";
}

/// The text of a simple element (no children) with this id.
std::string Text(const std::string& dom, const std::string& id) {
  std::smatch m;
  const std::regex element("id=\"" + id + "\"[^>]*>([^<]*)<");
  return std::regex_search(dom, m, element) ? m[1].str() : "";
}

std::string Digits(const std::string& text) {
  std::string digits;
  for (const char c : text) {
    if (c >= '0' && c <= '9') digits += c;
  }
  return digits;
}

/// An open /events stream held by the test, as a watching page would hold it.
class HeldStream {
 public:
  explicit HeldStream(int port) : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    const std::string request = "GET /events HTTP/1.1\r\nHost: x\r\n\r\n";
    char buffer[64];
    if (fd_ < 0 || connect(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0 ||
        write(fd_, request.data(), request.size()) != static_cast<ssize_t>(request.size()) ||
        read(fd_, buffer, sizeof(buffer)) <= 0) {  // served: the stream holds its place
      throw std::runtime_error("no stream");
    }
  }
  ~HeldStream() { close(fd_); }
  HeldStream(const HeldStream&) = delete;
  HeldStream& operator=(const HeldStream&) = delete;

 private:
  int fd_;
};

std::vector<std::string> ChromiumDumpDom(const fs::path& profile, int port,
                                         int virtual_budget_ms = 1000) {
  return {kChromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
          "--no-first-run", "--disable-background-networking", "--disable-component-update",
          "--disable-sync", "--user-data-dir=" + profile.string(),
          // Dumps once the stream has ended (see the top of this file).
          "--virtual-time-budget=" + std::to_string(virtual_budget_ms), "--dump-dom",
          "http://127.0.0.1:" + std::to_string(port) + "/"};
}

/// The robot's group: its data attributes are the record's numbers, and its transform draws
/// exactly them (rounded to the digits the page writes).
void ExpectRobotDrawnAt(const std::string& dom, const nlohmann::json& pose) {
  const std::string robot = Tag(dom, "robot");
  ASSERT_FALSE(robot.empty()) << dom;
  const double x = std::stod(Attribute(robot, "data-x"));
  const double y = std::stod(Attribute(robot, "data-y"));
  const double theta = std::stod(Attribute(robot, "data-theta"));
  EXPECT_EQ(x, pose["x"].get<double>());  // exact: both sides print shortest round-trip
  EXPECT_EQ(y, pose["y"].get<double>());
  EXPECT_EQ(theta, pose["theta"].get<double>());
  EXPECT_GT(x, 0.1) << "the input drives the robot forward";
  std::smatch m;
  const std::string transform = Attribute(robot, "transform");
  ASSERT_TRUE(
      std::regex_search(transform, m, std::regex(R"(translate\((\S+) (\S+)\) rotate\((\S+)\))")))
      << transform;
  EXPECT_NEAR(std::stod(m[1].str()), x, 5e-5);
  EXPECT_NEAR(std::stod(m[2].str()), y, 5e-5);
  EXPECT_NEAR(std::stod(m[3].str()), theta * 180.0 / std::numbers::pi, 5e-4);
}

/// Connections the server holds open on 127.0.0.1:`port` (ESTABLISHED, from /proc/net/tcp).
int ServerConnections(int port) {
  std::ifstream table("/proc/net/tcp");
  std::string line;
  std::getline(table, line);  // the header
  int count = 0;
  while (std::getline(table, line)) {
    std::istringstream fields(line);
    std::string slot, local, remote, state;
    fields >> slot >> local >> remote >> state;
    const std::size_t colon = local.find(':');
    if (colon != std::string::npos && state == "01" &&
        std::stoi(local.substr(colon + 1), nullptr, 16) == port) {
      ++count;
    }
  }
  return count;
}

TEST(TelemetryWeb, ChromiumDrawsTheRobotFromTheStream) {
  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << kChromium << " is missing (apt-get install chromium; scripts/setup.sh)";
  }
  const fs::path dir = TempDir("chromium");
  const int port = FreePort();
  // The twin runs until the page has its stream, then is stopped: Chromium took over 5 s to
  // start beside a loaded build, and a fixed 5 s twin had gone before the page asked (CI's
  // quick tier, locally). A stopped run still ends its stream with a final record. The robot
  // drives straight on at one duty, so whenever the page joins it sees it move (the built-in
  // profile rests for seconds, and a page that joined then drew a one-point trail).
  const fs::path input = dir / "straight_on.csv";
  std::ofstream(input) << "time,left,right\n0,0.5,0.5\n60,0.5,0.5\n";
  auto twin = test::Spawn({HILTWIN_BINARY, "run", "--rate", "1000", "--duration", "60", "--input",
                           input.string(), "--web", "127.0.0.1:" + std::to_string(port),
                           "--no-progress"},
                          (dir / "out.txt").string());
  ASSERT_TRUE(WaitUntilServing(port, std::chrono::seconds(20)));
  std::vector<nlohmann::json> streamed;
  std::thread reader([&] { streamed = ReadEvents(port); });
  auto chromium = test::Spawn(ChromiumDumpDom(dir / "profile", port), (dir / "dom").string());
  // This test's reader and the page: Chromium loads the page and opens its EventSource on one
  // kept-alive connection. Three seconds of records then reach the page (its script may run
  // a while after the page's connection opened, on a loaded machine).
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(50);
  while (ServerConnections(port) < 2 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::this_thread::sleep_for(std::chrono::seconds(3));
  // A loaded machine may flag the run (exit 3): what is tested here is the page.
  const int code = twin.Kill(SIGTERM).code;
  reader.join();
  EXPECT_TRUE(code == 0 || code == 3) << "exit " << code;
  const std::optional<kernel_glue::ExitStatus> chromium_end =
      chromium.WaitFor(std::chrono::seconds(120));
  const std::string chromium_err = test::ReadOutput((dir / "dom.err").string());
  ASSERT_TRUE(chromium_end.has_value()) << "Chromium still runs after 120 s" << chromium_err;
  ASSERT_EQ(chromium_end->code, 0) << chromium_end->Describe() << chromium_err;
  ASSERT_FALSE(streamed.empty());
  const nlohmann::json& last = streamed.back();
  ASSERT_TRUE(last["final"].get<bool>());
  const std::string dom = test::ReadOutput((dir / "dom").string());

  const std::string samples = Attribute(Tag(dom, "arena"), "data-samples");
  ASSERT_FALSE(samples.empty()) << "no page in the dump: " << chromium_err << dom;
  EXPECT_GE(std::stoi(samples), 5) << dom;
  ExpectRobotDrawnAt(dom, last["pose"]);
  const std::string points = Attribute(Tag(dom, "trail"), "points");
  EXPECT_GE(std::count(points.begin(), points.end(), ','), 3) << points;
  // The page's last record is the final one: it closes its stream on it.
  EXPECT_EQ(Text(dom, "t-state"), last["state"].get<std::string>() + " (final)");
  EXPECT_EQ(Text(dom, "t-verdict"), last["timing"]["verdict"].get<std::string>());
  EXPECT_EQ(Digits(Text(dom, "t-misses")),
            std::to_string(last["timing"]["deadline_misses"].get<std::uint64_t>()));
  for (const auto& [name, wheel] : last["wheels"].items()) {
    std::smatch m;
    ASSERT_TRUE(std::regex_search(dom, m, std::regex("<tr data-name=\"" + name + "\"[^>]*>")))
        << name;
    EXPECT_EQ(std::stod(Attribute(m[0].str(), "data-m")), wheel["m"].get<double>()) << name;
  }
  fs::remove_all(dir);
}

// Six pages watch (the most a run serves); a seventh used to show "connecting" forever: an
// EventSource given HTTP 503 gives up for good and says nothing. It must say why and retry.
// Its stream ends at once, so virtual time runs: 12 s of it cover the first connection and the
// retries 5 s and 10 s later.
TEST(TelemetryWeb, ChromiumAsSeventhPageSaysWhyItCannotConnectAndRetries) {
  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << kChromium << " is missing (apt-get install chromium; scripts/setup.sh)";
  }
  const fs::path dir = TempDir("seventh");
  const int port = FreePort();
  auto twin = test::Spawn({HILTWIN_BINARY, "run", "--rate", "200", "--duration", "60", "--web",
                           "127.0.0.1:" + std::to_string(port), "--no-progress"},
                          (dir / "out.txt").string());
  ASSERT_TRUE(WaitUntilServing(port, std::chrono::seconds(20)));
  std::vector<std::unique_ptr<HeldStream>> watching;
  for (int i = 0; i < 6; ++i) watching.push_back(std::make_unique<HeldStream>(port));
  const test::RunResult chromium =
      test::Run(ChromiumDumpDom(dir / "profile", port, 12'000), 60'000);
  watching.clear();
  static_cast<void>(twin.Kill(SIGTERM));
  ASSERT_EQ(chromium.exit_code, 0) << chromium.status.Describe() << chromium.err;
  const std::string& dom = chromium.out;
  const std::string link = Tag(dom, "link");
  EXPECT_EQ(Attribute(link, "class"), "busy") << link;
  EXPECT_NE(Text(dom, "link").find("6 pages already watch this run"), std::string::npos) << link;
  EXPECT_NE(Text(dom, "link").find("tries again every 5 s"), std::string::npos) << link;
  EXPECT_GE(std::stoi("0" + Attribute(link, "data-attempts")), 2) << "no retry: " << link;
  EXPECT_EQ(Attribute(Tag(dom, "arena"), "data-samples"), "0") << "no record was shown";
  fs::remove_all(dir);
}

// "0" is 0.0.0.0 to the resolver: the start-up line names the address really bound, and says
// that it means every interface.
TEST(TelemetryWeb, TheStartUpLineNamesTheAddressReallyBound) {
  const std::string port = std::to_string(FreePort());
  const test::RunResult r = test::Run({HILTWIN_BINARY, "run", "--duration", "0.2", "--web",
                                       "0:" + port, "--no-progress"});
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 3) << r.out << r.err;  // 3: a loaded machine
  EXPECT_NE(r.out.find("web page http://0.0.0.0:" + port + "/ (every interface"),
            std::string::npos)
      << r.out;
}

TEST(TelemetryWeb, APortInUseIsExitTwoNamingThePort) {
  const LoopbackSocket holder(true);
  const std::string port = std::to_string(holder.port());
  const test::RunResult r = test::Run(
      {HILTWIN_BINARY, "run", "--duration", "1", "--web", "127.0.0.1:" + port, "--no-progress"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("port " + port + " is already in use"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--web"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("verdict"), std::string::npos) << "the run must not start: " << r.out;
}

}  // namespace
}  // namespace hiltwin
