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
#include <functional>
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
#include "hiltwin/telemetry/record_json.h"
#include "hiltwin/telemetry/sinks.h"

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
                                         int virtual_budget_ms = 1000,
                                         const std::vector<std::string>& extra = {}) {
  std::vector<std::string> argv = {
      kChromium, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
      "--no-first-run", "--disable-background-networking", "--disable-component-update",
      "--disable-sync", "--user-data-dir=" + profile.string(),
      // Dumps once the stream has ended (see the top of this file).
      "--virtual-time-budget=" + std::to_string(virtual_budget_ms), "--dump-dom"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back("http://127.0.0.1:" + std::to_string(port) + "/");
  return argv;
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
  // This test's reader and the page's stream. The server keeps no connection alive, so the
  // page and three.js come on connections that close with their response; the page's
  // EventSource is the one that stays. A second connection held for a second is therefore the
  // stream (counting any second connection, a page whose script ran late under load 19 got
  // no record). Three seconds of records then reach the page.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(50);
  for (int held_ms = 0; held_ms < 1000 && std::chrono::steady_clock::now() < give_up;) {
    held_ms = ServerConnections(port) >= 2 ? held_ms + 50 : 0;
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

// ---- The page's drawing, measured in the browser. A page fed by a live twin receives
// whichever records the stream had when it looked; these tests need exact ones. So the test
// serves the page itself: the page and three.js exactly as the web sink serves them (fetched
// from one), a finite /events stream of records the test wrote (telemetry::ToJson, as the sink
// sends them), and, appended to the page, a probe script that measures what Chromium drew and
// writes it into <pre id="probe"> for --dump-dom.

// Measures, in screen pixels: every text of the 2D grid (axis labels and the scale bar's)
// once the run has ended; and the 3D canvas's robot-coloured pixels (count and centroid) after
// the first record and after the final one, with the count of the setpoint ghost's violet.
// The canvas keeps its last frame (preserveDrawingBuffer), which the page draws synchronously
// for those two records.
constexpr const char* kProbeScript = R"js(
(() => {
  const out = document.createElement("pre");
  out.id = "probe";
  document.body.appendChild(out);
  const result = { robot: [] };
  function robotPixels() {
    const gl = document.querySelector("#view3d canvas");
    if (!gl) return null;
    const copy = document.createElement("canvas");
    copy.width = gl.width; copy.height = gl.height;
    const ctx = copy.getContext("2d");
    ctx.drawImage(gl, 0, 0);
    const px = ctx.getImageData(0, 0, copy.width, copy.height).data;
    let n = 0, sx = 0, sy = 0, ghost = 0;
    for (let i = 0; i < px.length; i += 4) {
      const r = px[i], g = px[i + 1], b = px[i + 2];
      if (b > 100 && b > r + 60 && b > g + 40) {  // the body's blue, lit or in shade
        const p = i / 4; n += 1; sx += p % copy.width; sy += Math.floor(p / copy.width);
      } else if (r > g + 15 && b > g + 50) {  // the ghost's see-through violet over the floor
        ghost += 1;
      }
    }
    return { n, x: n ? sx / n : 0, y: n ? sy / n : 0, ghost };
  }
  function labels() {
    return [...document.querySelectorAll("#grid text")].map((t) => {
      const r = t.getBoundingClientRect();
      return { text: t.textContent, l: r.left, t: r.top, r: r.right, b: r.bottom };
    });
  }
  new MutationObserver(() => {
    const first = document.getElementById("arena").dataset.samples === "1";
    if (first && result.robot.length === 0) result.robot.push(robotPixels());
  }).observe(document.getElementById("arena"), { attributes: true });
  new MutationObserver(() => {
    if (document.getElementById("link").textContent !== "run ended") return;
    const a = document.getElementById("arena").getBoundingClientRect();
    result.arena = { l: a.left, t: a.top, r: a.right, b: a.bottom };
    result.labels = labels();
    result.robot.push(robotPixels());
    out.textContent = JSON.stringify(result);
  }).observe(document.getElementById("link"), { childList: true, characterData: true, subtree: true });
})();
)js";

/// A twin's record at this pose and time; `final` ends the page's stream.
runtime::TelemetryRecord PoseRecord(double x, double y, double theta, double t, bool final) {
  runtime::TelemetryRecord r;
  r.ns = "bench";
  r.role = "twin";
  r.rate_hz = 1000.0;
  r.time_s = t;
  r.cycle = static_cast<std::uint64_t>(t * 1000.0);
  r.cycles_planned = 2000;
  r.state = final ? lifecycle::State::kStopped : lifecycle::State::kRun;
  r.final = final;
  r.latency_samples = 1000;
  r.task.has_pose = true;
  r.task.x_m = x;
  r.task.y_m = y;
  r.task.theta_rad = theta;
  r.task.joint_count = 2;
  r.task.joint_position_m = {0.5 * t, 0.6 * t, 0.0, 0.0};
  r.task.joint_position_rad = {0.5 * t / 0.04, 0.6 * t / 0.04, 0.0, 0.0};
  r.joint_names = {"wheel_left_joint", "wheel_right_joint"};
  return r;
}

/// httplib's task queue that runs each connection at once, on the thread that accepted it.
class ServeInline : public httplib::TaskQueue {
 public:
  void enqueue(std::function<void()> fn) override { fn(); }
  void shutdown() override {}
};

/// The page, its three.js and `records` as one finite /events stream, with the probe.
class ProbedPage {
 public:
  explicit ProbedPage(const std::vector<runtime::TelemetryRecord>& records) {
    const std::shared_ptr<runtime::TelemetrySink> sink = telemetry::MakeWebSink({"127.0.0.1", 0});
    sink->Open(runtime::TelemetryShape{}, "bench");
    std::smatch m;
    const std::string url = sink->Describe();
    if (!std::regex_search(url, m, std::regex(R"(:(\d+)/)"))) throw std::runtime_error(url);
    httplib::Client client("127.0.0.1", std::stoi(m[1].str()));
    const httplib::Result page = client.Get("/");
    const httplib::Result three = client.Get("/three.min.js");
    if (!page || !three) throw std::runtime_error("the web sink did not serve the page");
    page_ = page->body;
    page_.insert(page_.rfind("</body>"), std::string("<script>") + kProbeScript + "</script>");
    three_status_ = three->status;
    three_ = three->body;
    for (const runtime::TelemetryRecord& r : records) {
      events_ += "data: " + telemetry::ToJson(r).dump() + "\n\n";
    }
    Serve();
  }
  ~ProbedPage() {
    // stop() is a no-op until listen_after_bind has marked the server running.
    while (!server_.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    server_.stop();
    thread_.join();
  }
  ProbedPage(const ProbedPage&) = delete;
  ProbedPage& operator=(const ProbedPage&) = delete;
  [[nodiscard]] int port() const noexcept { return port_; }

 private:
  void Serve() {
    server_.Get("/", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(page_, "text/html; charset=utf-8");
    });
    server_.Get("/three.min.js", [this](const httplib::Request&, httplib::Response& res) {
      res.status = three_status_;
      res.set_content(three_, "text/javascript; charset=utf-8");
    });
    server_.Get("/events", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(events_, "text/event-stream");
    });
    // Every connection is served on the listening thread, one request each: httplib's own
    // pool hands a connection to a worker inside the library, which is not built with TSan,
    // so the TSan build saw the listener's allocation freed by a worker as a data race. A
    // test's page needs no parallel serving: Chromium's other connections wait in the backlog.
    server_.new_task_queue = [] { return new ServeInline; };
    server_.set_keep_alive_max_count(1);
    port_ = server_.bind_to_any_port("127.0.0.1");
    // Bound is listening: a browser's connection waits in the backlog until the thread runs.
    thread_ = std::thread([this] { server_.listen_after_bind(); });
  }

  std::string page_, three_, events_;
  int three_status_ = 0;
  httplib::Server server_;
  int port_ = 0;
  std::thread thread_;
};

/// What the probe wrote, as JSON (null when the page never ended its run).
nlohmann::json Probe(const std::string& dom) {
  const std::string open = "<pre id=\"probe\">";
  const std::size_t start = dom.find(open);
  const std::size_t end = dom.find("</pre>", start);
  if (start == std::string::npos || end == std::string::npos) return {};
  std::string text = dom.substr(start + open.size(), end - start - open.size());
  for (const auto& [entity, c] : {std::pair{"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
    for (std::size_t at = text.find(entity); at != std::string::npos; at = text.find(entity)) {
      text.replace(at, std::string(entity).size(), c);
    }
  }
  return text.empty() ? nlohmann::json() : nlohmann::json::parse(text);
}

/// Loads the page in Chromium (1280x800) and returns the dumped DOM.
std::string LoadProbed(const char* name, const ProbedPage& page,
                       const std::vector<std::string>& flags = {}) {
  const fs::path dir = TempDir(name);
  std::vector<std::string> extra = {"--window-size=1280,800"};
  extra.insert(extra.end(), flags.begin(), flags.end());
  const test::RunResult chromium =
      test::Run(ChromiumDumpDom(dir / "profile", page.port(), 3000, extra), 120'000);
  fs::remove_all(dir);
  EXPECT_EQ(chromium.exit_code, 0) << chromium.status.Describe() << chromium.err;
  return chromium.out;
}

struct Box {
  std::string text;
  double l, t, r, b;
};

/// The texts of the grid a user sees: those the arena does not clip away entirely.
std::vector<Box> VisibleLabels(const nlohmann::json& probe, const Box& arena) {
  std::vector<Box> boxes;
  for (const auto& j : probe["labels"]) {
    const Box b{j["text"].get<std::string>(), j["l"].get<double>(), j["t"].get<double>(),
                j["r"].get<double>(), j["b"].get<double>()};
    if (b.l < arena.r && arena.l < b.r && b.t < arena.b && arena.t < b.b) boxes.push_back(b);
  }
  return boxes;
}

std::string Describe(const Box& b) {
  return "'" + b.text + "' at (" + std::to_string(b.l) + ", " + std::to_string(b.t) + ")-(" +
         std::to_string(b.r) + ", " + std::to_string(b.b) + ")";
}

// The robot stands still at (0.28 m, 0.28 m): the view is then 1.6 m square from
// (-0.52, -0.52), a grid line 0.02 m inside its bottom and its left edge, and the x label "-0.5"
// and the y label "-0.5" were drawn over each other in the bottom-left corner. No two visible
// texts of the grid may overlap, none may be cut by the arena's edge, and both axes keep labels.
TEST(TelemetryWeb, ChromiumAxisLabelsDoNotOverlap) {
  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << kChromium << " is missing (apt-get install chromium; scripts/setup.sh)";
  }
  std::vector<runtime::TelemetryRecord> records;
  for (int i = 0; i <= 5; ++i) records.push_back(PoseRecord(0.28, 0.28, 0.3, 0.1 * i, i == 5));
  const ProbedPage page(records);
  const std::string dom = LoadProbed("labels", page);
  const nlohmann::json probe = Probe(dom);
  ASSERT_TRUE(probe.is_object()) << "the page did not end its run: " << dom;
  const nlohmann::json& a = probe["arena"];
  const Box arena{"arena", a["l"].get<double>(), a["t"].get<double>(), a["r"].get<double>(),
                  a["b"].get<double>()};
  const std::vector<Box> boxes = VisibleLabels(probe, arena);
  int left_column = 0, bottom_row = 0;
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Box& b = boxes[i];
    const bool inside = b.l >= arena.l - 0.5 && b.r <= arena.r + 0.5 && b.t >= arena.t - 0.5 &&
                        b.b <= arena.b + 0.5;
    EXPECT_TRUE(inside) << Describe(b) << " is cut by the arena's edge " << Describe(arena);
    left_column += b.l < arena.l + 20.0 ? 1 : 0;
    bottom_row += b.b > arena.b - 20.0 ? 1 : 0;
    for (std::size_t j = i + 1; j < boxes.size(); ++j) {
      const Box& c = boxes[j];
      EXPECT_FALSE(b.l < c.r && c.l < b.r && b.t < c.b && c.t < b.b)
          << Describe(b) << " overlaps " << Describe(c);
    }
  }
  EXPECT_GE(left_column, 2) << "y labels along the left edge: " << probe["labels"].dump();
  EXPECT_GE(bottom_row, 2) << "x labels along the bottom edge: " << probe["labels"].dump();
}

/// The 3D view's attributes as numbers.
double Data3d(const std::string& dom, const char* name) {
  return std::stod("0" + Attribute(Tag(dom, "view3d"), name));
}

// Thesis §3.10 (Should 2), "3D visualisation": the robot drives 0.3 m forward while turning and
// its wheels turn. Software WebGL (SwiftShader) draws in headless Chromium; the canvas shows the
// robot's body after the first record and after the final one, moved across the picture, and
// the 3D model's pose and wheel angles are the final record's.
TEST(TelemetryWeb, Chromium3dViewDrawsTheRobotMoving) {
  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << kChromium << " is missing (apt-get install chromium; scripts/setup.sh)";
  }
  std::vector<runtime::TelemetryRecord> records;
  constexpr int kLast = 20;
  for (int i = 0; i <= kLast; ++i) {
    const double s = static_cast<double>(i) / kLast;
    records.push_back(PoseRecord(0.3 * s, 0.05 * s, 0.4 * s, 2.0 * s, i == kLast));
  }
  const ProbedPage page(records);
  const std::string dom = LoadProbed("3d", page, {"--enable-unsafe-swiftshader"});
  const std::string view = Tag(dom, "view3d");
  ASSERT_EQ(Attribute(view, "data-state"), "webgl") << Text(dom, "view3d-note") << view;
  EXPECT_GE(Data3d(dom, "data-frames"), 2.0) << view;
  const nlohmann::json last = telemetry::ToJson(records.back());
  EXPECT_DOUBLE_EQ(Data3d(dom, "data-x"), last["pose"]["x"].get<double>()) << view;
  EXPECT_DOUBLE_EQ(Data3d(dom, "data-y"), last["pose"]["y"].get<double>()) << view;
  EXPECT_DOUBLE_EQ(Data3d(dom, "data-theta"), last["pose"]["theta"].get<double>()) << view;
  EXPECT_DOUBLE_EQ(Data3d(dom, "data-wheel-left"),
                   last["wheels"]["wheel_left_joint"]["rad"].get<double>()) << view;
  EXPECT_DOUBLE_EQ(Data3d(dom, "data-wheel-right"),
                   last["wheels"]["wheel_right_joint"]["rad"].get<double>()) << view;
  const nlohmann::json probe = Probe(dom);
  ASSERT_TRUE(probe.is_object()) << "the page did not end its run: " << dom;
  const nlohmann::json& robot = probe["robot"];
  RecordProperty("robot_pixels", robot.dump());  // --gtest_output=xml shows the figures
  ASSERT_EQ(robot.size(), 2U) << robot.dump();
  ASSERT_TRUE(robot[0].is_object() && robot[1].is_object()) << "no canvas: " << robot.dump();
  EXPECT_GE(robot[0]["n"].get<int>(), 100) << "no robot in the first frame: " << robot.dump();
  EXPECT_GE(robot[1]["n"].get<int>(), 100) << "no robot in the last frame: " << robot.dump();
  const double moved = std::hypot(robot[1]["x"].get<double>() - robot[0]["x"].get<double>(),
                                  robot[1]["y"].get<double>() - robot[0]["y"].get<double>());
  EXPECT_GE(moved, 30.0) << "the robot did not move across the picture: " << robot.dump();
}

// Issue 35, the setpoint: a controller's records carry its wheels' setpoints, and the page drives
// a ghost robot with them beside the real one, in 2D and 3D, labelled "setpoint". The left
// wheel's setpoint goes 0 -> 0.3 m and the right's 0 -> 0.5 m at constant speeds over 2 s: a
// circular arc of radius 0.17/2 · 0.8/0.2 = 0.34 m turning (0.5 - 0.3)/0.17 = 1.18 rad, which
// the page's arcs reproduce exactly. The real robot lags behind on a straight line.
TEST(TelemetryWeb, ChromiumDrawsTheSetpointAsAGhostRobotIn2dAnd3d) {
  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << kChromium << " is missing (apt-get install chromium; scripts/setup.sh)";
  }
  constexpr double kTrack = 0.17, kLeft = 0.3, kRight = 0.5;
  std::vector<runtime::TelemetryRecord> records;
  constexpr int kLast = 20;
  for (int i = 0; i <= kLast; ++i) {
    const double s = static_cast<double>(i) / kLast;
    records.push_back(PoseRecord(0.2 * s, 0.0, 0.0, 2.0 * s, i == kLast));
    records.back().task.has_setpoint = true;
    records.back().task.joint_setpoint_m = {kLeft * s, kRight * s, 0.0, 0.0};
  }
  const double theta = (kRight - kLeft) / kTrack;
  const double radius = kTrack / 2.0 * (kRight + kLeft) / (kRight - kLeft);
  const double x = radius * std::sin(theta), y = radius * (1.0 - std::cos(theta));
  const ProbedPage page(records);
  const std::string dom = LoadProbed("setpoint", page, {"--enable-unsafe-swiftshader"});
  const std::string ghost = Tag(dom, "ghost");
  ASSERT_FALSE(ghost.empty()) << dom;
  EXPECT_EQ(Attribute(ghost, "display"), "inline") << ghost;
  EXPECT_NEAR(std::stod("0" + Attribute(ghost, "data-x")), x, 1e-9) << ghost;
  EXPECT_NEAR(std::stod("0" + Attribute(ghost, "data-y")), y, 1e-9) << ghost;
  EXPECT_NEAR(std::stod("0" + Attribute(ghost, "data-theta")), theta, 1e-9) << ghost;
  EXPECT_EQ(Text(dom, "ghost-label"), "setpoint");
  EXPECT_EQ(Attribute(Tag(dom, "ghost-label"), "display"), "inline");
  ExpectRobotDrawnAt(dom, telemetry::ToJson(records.back())["pose"]);  // the robot as before
  const std::string view = Tag(dom, "view3d");
  ASSERT_EQ(Attribute(view, "data-state"), "webgl") << Text(dom, "view3d-note") << view;
  EXPECT_NEAR(Data3d(dom, "data-ghost-x"), x, 1e-9) << view;
  EXPECT_NEAR(Data3d(dom, "data-ghost-y"), y, 1e-9) << view;
  EXPECT_NEAR(Data3d(dom, "data-ghost-theta"), theta, 1e-9) << view;
  EXPECT_DOUBLE_EQ(Data3d(dom, "data-x"), 0.2) << view;
  const nlohmann::json probe = Probe(dom);
  ASSERT_TRUE(probe.is_object()) << "the page did not end its run: " << dom;
  const nlohmann::json& frames = probe["robot"];
  RecordProperty("frames", frames.dump());
  ASSERT_EQ(frames.size(), 2U) << frames.dump();
  ASSERT_TRUE(frames[1].is_object()) << "no canvas: " << frames.dump();
  EXPECT_GE(frames[1]["ghost"].get<int>(), 100) << "no ghost in the last frame: " << frames.dump();
  EXPECT_GE(frames[1]["n"].get<int>(), 100) << "no robot in the last frame: " << frames.dump();
}

// Without WebGL the page says so where the 3D view would be, and the 2D view works as before.
TEST(TelemetryWeb, ChromiumWithoutWebglSaysSoAndDrawsIn2d) {
  if (!fs::exists(kChromium)) {
    GTEST_SKIP() << kChromium << " is missing (apt-get install chromium; scripts/setup.sh)";
  }
  std::vector<runtime::TelemetryRecord> records;
  for (int i = 0; i <= 4; ++i) records.push_back(PoseRecord(0.1 * i, 0.0, 0.0, 0.5 * i, i == 4));
  const ProbedPage page(records);
  const std::string dom = LoadProbed("nowebgl", page, {"--disable-webgl"});
  EXPECT_EQ(Attribute(Tag(dom, "view3d"), "data-state"), "no-webgl") << Tag(dom, "view3d");
  const std::string note = Text(dom, "view3d-note");
  EXPECT_NE(note.find("no WebGL"), std::string::npos) << note;
  EXPECT_NE(note.find("the 2D view shows the pose"), std::string::npos) << note;
  EXPECT_EQ(Attribute(Tag(dom, "arena"), "data-samples"), "5") << dom;
  ExpectRobotDrawnAt(dom, telemetry::ToJson(records.back())["pose"]);
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
