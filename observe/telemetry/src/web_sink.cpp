// The live web page (`--web ADDR:PORT`): the page itself, a Server-Sent Events stream of the
// telemetry records and the latest record as JSON, served by cpp-httplib on threads of our
// own. The telemetry thread only swaps a pointer and notifies; every browser is served from
// its own worker, so a slow one delays nobody but itself.

#include <httplib.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "hiltwin/kernel_glue/thread.h"
#include "hiltwin/telemetry/record_json.h"
#include "hiltwin/telemetry/sinks.h"
#include "web_bind.h"
#include "web_latest.h"
#include "web_page.h"
#include "web_workers.h"

namespace hiltwin::telemetry {
namespace {

// A comment on an idle stream (a paused run, a slow rate) keeps the connection from looking
// dead to the browser, and a closed browser shows up as a failed write within this time.
constexpr std::chrono::milliseconds kKeepAlive{2000};
// How long an EventSource waits before it reconnects (e.g. to the next run on the same port).
constexpr const char* kRetryHint = "retry: 1000\n\n";
// Each /events stream holds a worker for its whole life: six pages may watch, and eight more
// workers are always left for the page itself, /record and connections that never send a
// request (each of those costs a worker about 10 ms, see Configure).
constexpr int kMaxStreams = 6;
constexpr std::size_t kRequestWorkers = 8;
constexpr std::size_t kWorkers = kMaxStreams + kRequestWorkers;
// Connections held at once, queued or being served; beyond it the accept loop waits and new
// connections wait in the kernel's listen queue (web_workers.h).
constexpr std::size_t kMaxConnections = 128;
// How long the kernel keeps a connection that has sent nothing before handing it over anyway
// (TCP_DEFER_ACCEPT, see Configure).
constexpr int kDeferAcceptS = 1;
// How long one stuck connection (a request that stops halfway, a stream whose browser does not
// read) may hold a worker per read or write, and so the longest the destructor waits for a
// worker that is not inside a stream (streams end at once on Stop).
constexpr time_t kSocketTimeoutS = 1;
// What a page beyond kMaxStreams gets instead of a stream: an EventSource treats every status
// but 200 as the end for good (the page would say "connecting" forever), so a page is served
// one `busy` event that says why, and `retry:` makes the browser try again on its own.
constexpr int kBusyRetryS = 5;
// How long the destructor lets open streams send their last record (a stream whose client
// does not read is cut off after this).
constexpr std::chrono::milliseconds kDrainTimeout{300};

// One open /events stream: what it sent last, and its place in the stream count (released
// when httplib drops the response, however the stream ended).
struct Stream {
  explicit Stream(std::atomic<int>& open) noexcept : open_count(open) {}
  ~Stream() { open_count.fetch_sub(1); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  std::atomic<int>& open_count;
  std::uint64_t seen = 0;
  bool greeted = false;
};

bool Write(httplib::DataSink& sink, const std::string& text) {
  return sink.write(text.data(), text.size());
}

// httplib's server, with the socket it listens on (httplib keeps it protected): the sink names
// the address the socket really has.
class Server final : public httplib::Server {
 public:
  [[nodiscard]] socket_t ListeningSocket() const noexcept { return svr_sock_; }
};

// The one event a page beyond kMaxStreams gets (docs/telemetry.md, "The web page").
std::string BusyEvent() {
  const nlohmann::json busy = {
      {"message", std::to_string(kMaxStreams) +
                      " pages already watch this run (the most it serves): close one of them; "
                      "this page tries again every " +
                      std::to_string(kBusyRetryS) + " s"},
      {"retry_s", kBusyRetryS}};
  return "retry: " + std::to_string(kBusyRetryS * 1000) + "\nevent: busy\ndata: " + busy.dump() +
         "\n\n";
}

// three.js for the page's 3D view (0.85 MB). Not cached, as the page is not: the next run on
// this port may be another hiltwin with another three.js, and its page is written for that one.
// Served as it is from the binary, through a content provider: httplib compresses a body set
// with set_content per request (brotli, when the browser accepts it), which took 6 s for this
// file on a loaded 2-core machine, and a 20 s run had ended before its page connected.
void ServeThreeJs(httplib::Response& res) {
  const std::string_view script = web::ThreeJs();
  if (script.empty()) {
    res.status = 404;
    res.set_content("this hiltwin was built without three.js (-DHILTWIN_WEB_3D=OFF): the page "
                    "shows its 2D view only",
                    "text/plain");
    return;
  }
  res.set_header("Cache-Control", "no-store");
  res.set_content_provider(script.size(), "text/javascript; charset=utf-8",
                           [script](std::size_t offset, std::size_t length,
                                    httplib::DataSink& sink) {
                             return sink.write(script.data() + offset, length);
                           });
}

bool WantsEventStream(const httplib::Request& req) {
  return req.get_header_value("Accept").find("text/event-stream") != std::string::npos;
}

class WebSink final : public runtime::TelemetrySink {
 public:
  explicit WebSink(const WebEndpoint& endpoint);
  ~WebSink() override;
  WebSink(const WebSink&) = delete;
  WebSink& operator=(const WebSink&) = delete;

  void Open(const runtime::TelemetryShape& shape, const std::string& ns) override;
  void Publish(const runtime::TelemetryRecord& record) noexcept override;
  [[nodiscard]] std::string Describe() const override;

 private:
  void Configure();
  void Bind();
  void StartServing();
  void ServeRecord(httplib::Response& res) const;
  void ServeEvents(const httplib::Request& req, httplib::Response& res);
  bool StreamStep(Stream& stream, httplib::DataSink& sink);

  WebEndpoint endpoint_;
  web::LatestRecord latest_;
  std::atomic<int> open_streams_{0};
  Server server_;
  std::atomic<bool> listen_returned_{false};
  kernel_glue::NamedThread listener_;
};

WebSink::WebSink(const WebEndpoint& endpoint) : endpoint_(endpoint) {
  Configure();
  Bind();
}

WebSink::~WebSink() {
  latest_.Stop();  // every stream sends what it has not sent yet and ends its response
  // ... before the listener stops: httplib stops calling a stream's provider once its
  // listening socket is closed, and the record a stream has not sent yet is usually the
  // run's final one.
  const auto give_up = std::chrono::steady_clock::now() + kDrainTimeout;
  while (open_streams_ > 0 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  try {
    // httplib closes its bound socket only from a running listener: a sink that was never
    // opened starts one just to stop it, so the port is free when the sink is gone.
    if (!listener_.joinable()) StartServing();
  } catch (...) {
    return;  // no thread could be made: nothing to stop either
  }
  // httplib's stop() is a no-op until listen_after_bind has marked the server running (its
  // first statement), so a sink destroyed right after Open waits for that, or the listener
  // would accept forever.
  while (!server_.is_running() && !listen_returned_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (!listen_returned_) server_.stop();
  listener_.Join();
}

void WebSink::Configure() {
  // httplib's default sets SO_REUSEPORT, which lets a second server bind a port that is in
  // use (and share its connections). SO_REUSEADDR alone still allows a restart right after
  // a run, while the last connections sit in TIME_WAIT.
  server_.set_socket_options([](socket_t sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    // The kernel hands a connection over only once its request has arrived (or, one that
    // sends nothing, after this time): a connection that sends nothing never takes a worker
    // or a descriptor meanwhile, and one the accept loop takes has its request there already,
    // however late a loaded browser wrote it after connecting.
    const int defer_s = kDeferAcceptS;
    setsockopt(sock, IPPROTO_TCP, TCP_DEFER_ACCEPT, &defer_s, sizeof(defer_s));
  });
  // One request per connection: an idle keep-alive connection would hold a worker, and
  // httplib does not look at stop() while it waits for the next request.
  server_.set_keep_alive_max_count(1);
  // How long a taken-up connection may stay silent before its request starts: 0 s is httplib's
  // shortest, one 10 ms poll. The kernel hands over connections whose request is there
  // (TCP_DEFER_ACCEPT above); one that still sends nothing after kDeferAcceptS (a port scanner,
  // a browser's spare socket) held a worker a whole second before, and 500 of them kept
  // /record waiting over 40 s.
  server_.set_keep_alive_timeout(0);
  server_.set_read_timeout(kSocketTimeoutS, 0);
  server_.set_write_timeout(kSocketTimeoutS, 0);
  server_.new_task_queue = [] {
    return new web::Workers(kWorkers, kMaxConnections, "hiltwin-web");
  };

  server_.Get("/", [](const httplib::Request&, httplib::Response& res) {
    const std::string_view page = web::PageHtml();
    res.set_header("Cache-Control", "no-store");
    res.set_content(page.data(), page.size(), "text/html; charset=utf-8");
  });
  server_.Get("/three.min.js", [](const httplib::Request&, httplib::Response& res) {
    ServeThreeJs(res);
  });
  server_.Get("/record",
              [this](const httplib::Request&, httplib::Response& res) { ServeRecord(res); });
  server_.Get("/events", [this](const httplib::Request& req, httplib::Response& res) {
    ServeEvents(req, res);
  });
}

void WebSink::Bind() {
  bool bound = false;
  if (endpoint_.port == 0) {  // any free port: Describe() then names the one chosen
    const int port = server_.bind_to_any_port(endpoint_.address);
    bound = port > 0;
    if (bound) endpoint_.port = static_cast<std::uint16_t>(port);
  } else {
    bound = server_.bind_to_port(endpoint_.address, endpoint_.port);
  }
  if (!bound) {
    throw std::invalid_argument(web::BindFailureMessage(endpoint_, web::ProbeBind(endpoint_)));
  }
  // httplib listens with a backlog of 5. Connections wait in the kernel while their request is
  // deferred, and when kMaxConnections are held: beyond the backlog the kernel would fall back
  // to SYN cookies, which hand a connection over without waiting for its request.
  listen(server_.ListeningSocket(), static_cast<int>(kMaxConnections));
  // What the socket really has ("0" is 0.0.0.0, "localhost" one of its addresses), for the
  // start-up line.
  if (const auto real = web::BoundEndpoint(server_.ListeningSocket())) endpoint_ = *real;
}

void WebSink::Open(const runtime::TelemetryShape& shape, const std::string& ns) {
  static_cast<void>(shape);  // every record names its namespace, role and joints itself
  static_cast<void>(ns);
  if (!listener_.joinable()) StartServing();
}

void WebSink::StartServing() {
  listener_ = kernel_glue::NamedThread({"hiltwin-web-lsn", kernel_glue::AllowedCpus()}, [this] {
    try {
      server_.listen_after_bind();
    } catch (...) {  // workers could not start: the page is gone, the run goes on
    }
    listen_returned_ = true;
  });
}

void WebSink::ServeRecord(httplib::Response& res) const {
  const web::LatestRecord::Next latest = latest_.Latest();
  res.set_header("Cache-Control", "no-store");
  if (!latest.json) {
    res.status = 503;
    res.set_header("Retry-After", "1");
    res.set_content(R"({"error": "no record yet: the run has not published one"})",
                    "application/json");
    return;
  }
  res.set_content(*latest.json, "application/json");
}

void WebSink::ServeEvents(const httplib::Request& req, httplib::Response& res) {
  if (open_streams_.fetch_add(1) >= kMaxStreams) {
    open_streams_.fetch_sub(1);
    res.set_header("Cache-Control", "no-store");
    res.set_header("Retry-After", std::to_string(kBusyRetryS));
    if (WantsEventStream(req)) {  // a page: see kBusyRetryS
      res.set_content(BusyEvent(), "text/event-stream");
      return;
    }
    res.status = 503;
    res.set_content(
        "too many open pages (at most " + std::to_string(kMaxStreams) + "): close one and reload",
        "text/plain");
    return;
  }
  res.set_header("Cache-Control", "no-store");
  auto stream = std::make_shared<Stream>(open_streams_);
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, stream](std::size_t, httplib::DataSink& sink) { return StreamStep(*stream, sink); });
}

// httplib calls this again for as long as it returns true and the server runs; each call
// sends one event (the newest record), a keep-alive comment, or the end of the stream.
bool WebSink::StreamStep(Stream& stream, httplib::DataSink& sink) {
  if (!stream.greeted) {
    stream.greeted = true;
    if (!Write(sink, kRetryHint)) return false;
  }
  const web::LatestRecord::Next next = latest_.WaitNewer(stream.seen, kKeepAlive);
  if (next.stopped) {
    sink.done();
    return true;
  }
  if (!next.json) return Write(sink, ": keep-alive\n\n");
  stream.seen = next.seq;
  std::string event;
  event.reserve(next.json->size() + 8);
  event.append("data: ").append(*next.json).append("\n\n");
  return Write(sink, event);
}

void WebSink::Publish(const runtime::TelemetryRecord& record) noexcept {
  try {
    // replace, not throw, on a bad byte: a namespace typo must not cost the stream
    std::string json =
        ToJson(record).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    latest_.Store(std::make_shared<const std::string>(std::move(json)));
  } catch (...) {  // out of memory: this record is lost, the next one replaces it
  }
}

std::string WebSink::Describe() const {
  std::string url = "web page " + web::UrlOf(endpoint_);
  if (!web::IsEveryInterface(endpoint_.address)) return url;
  return url + " (every interface: open it at this machine's name or address)";
}

}  // namespace

std::shared_ptr<runtime::TelemetrySink> MakeWebSink(const WebEndpoint& endpoint) {
  return std::make_shared<WebSink>(endpoint);
}

}  // namespace hiltwin::telemetry
