#include "http_server.h"

#include <restinio/all.hpp>
#include <restinio/helpers/http_field_parsers/content-disposition.hpp>
#include <restinio/helpers/multipart_body.hpp>

#include <malloc.h>

#include <algorithm>
#include <csignal>
#include <iostream>
#include <mutex>
#include <thread>
#include <unordered_map>

#include "api.h"
#include "storage.h"
#include "http_errors.h"
#include "routes.h"

namespace solidtex::server {
namespace {

// Flags of in-flight requests per connection, raised when the connection closes so that their
// interrupters cancel the work nobody will read.
class DisconnectRegistry {
 public:
  void add(std::uint64_t connection, const std::shared_ptr<std::atomic<bool>>& flag) {
    std::lock_guard<std::mutex> g(mutex_);
    auto& v = flags_[connection];
    std::erase_if(v, [](const auto& w) { return w.expired(); });
    v.push_back(flag);
  }
  void closed(std::uint64_t connection) {
    std::lock_guard<std::mutex> g(mutex_);
    auto it = flags_.find(connection);
    if (it == flags_.end()) return;
    for (auto& w : it->second)
      if (auto f = w.lock()) f->store(true);
    flags_.erase(it);
  }

 private:
  std::mutex mutex_;
  std::unordered_map<std::uint64_t, std::vector<std::weak_ptr<std::atomic<bool>>>> flags_;
};

DisconnectRegistry& registry() {
  static DisconnectRegistry r;
  return r;
}

struct ConnectionListener {
  void state_changed(const restinio::connection_state::notice_t& notice) noexcept {
    if (restinio::holds_alternative<restinio::connection_state::closed_t>(notice.cause()))
      registry().closed(notice.connection_id());
  }
};

struct Traits : public restinio::default_traits_t {
  using connection_state_listener_t = ConnectionListener;
};

const char* reason_phrase(int status) {
  switch (status) {
    case 200: return "OK";
    case 201: return "Created";
    case 202: return "Accepted";
    case 204: return "No Content";
    case 206: return "Partial Content";
    case 304: return "Not Modified";
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 409: return "Conflict";
    case 413: return "Payload Too Large";
    case 415: return "Unsupported Media Type";
    case 416: return "Range Not Satisfiable";
    case 422: return "Unprocessable Entity";
    case 429: return "Too Many Requests";
    case 500: return "Internal Server Error";
    case 502: return "Bad Gateway";
    case 503: return "Service Unavailable";
    case 504: return "Gateway Timeout";
  }
  return "Unknown";
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Media type without parameters, lower case, trimmed.
std::string media_type(const std::string& header) {
  std::string t = lower(header.substr(0, header.find(';')));
  while (!t.empty() && (t.back() == ' ' || t.back() == '\t')) t.pop_back();
  while (!t.empty() && (t.front() == ' ' || t.front() == '\t')) t.erase(t.begin());
  return t;
}

class Server {
 public:
  explicit Server(const ServerConfig& config) : config_(config) {}

  Status run() {
    std::vector<std::string> report;
    SOLIDTEX_ASSIGN_OR_RETURN(store_, open_storage(config_.storage_config(), &report));
    exemplars_ = std::make_unique<ExemplarService>(*store_, config_);
    fields_ = std::make_unique<FieldService>(*store_, config_);
    meshes_ = std::make_unique<MeshService>(*store_, config_);
    volumes_ = std::make_unique<VolumeService>(*store_, config_, *exemplars_, *fields_, *meshes_);
    // Memory a request freed goes back to the system once no request runs (README, "Memory"):
    // otherwise glibc keeps it in the arena of whichever thread freed it, where another
    // thread's next request cannot reuse it, and the process grows by a request's working memory
    // per arena.
    pool_ = std::make_unique<WorkerPool>(config_.threads, config_.queue, [] { malloc_trim(0); });
    api_ = std::make_unique<Api>(config_, *exemplars_, *fields_, *volumes_, *meshes_, metrics_, *pool_, stopping_, abort_running_);
    SOLIDTEX_RETURN_IF_ERROR(fields_->start(&report));
    SOLIDTEX_RETURN_IF_ERROR(exemplars_->start(&report));
    SOLIDTEX_RETURN_IF_ERROR(meshes_->start(&report));
    SOLIDTEX_RETURN_IF_ERROR(volumes_->start(&report));
    for (const std::string& line : report) std::cerr << "solidtex serve: " << line << "\n";

    // Signals go to the main thread only (sigwait below), never to I/O or worker threads.
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGTERM);
    sigaddset(&signals, SIGINT);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);

    auto settings = restinio::server_settings_t<Traits>{}
                        .address(config_.host)
                        .port(std::uint16_t(config_.port))
                        .connection_state_listener(std::make_shared<ConnectionListener>())
                        .request_handler([this](restinio::request_handle_t req) { return handle(std::move(req)); })
                        // Our own limit answers 413; RESTinio's hard cap (beyond it, it drops the
                        // connection) is four times larger so that most oversized bodies get the 413.
                        .incoming_http_msg_limits(restinio::incoming_http_msg_limits_t{}.max_body_size(
                            std::uint64_t(config_.max_upload_bytes) * 4))
                        // Keep reading while a request is in progress, so that a client hanging up
                        // is noticed (connection_state_listener) and its work cancelled.
                        .max_pipelined_requests(4)
                        // Deadlines are ours (504); RESTinio's timeout only catches stuck requests.
                        .handle_request_timeout(std::chrono::seconds(int64_t(config_.max_deadline_s) + 120))
                        .read_next_http_message_timelimit(std::chrono::seconds(120))
                        .write_http_response_timelimit(std::chrono::seconds(120));
    std::unique_ptr<restinio::running_server_instance_t<restinio::http_server_t<Traits>>> running;
    try {
      running = restinio::run_async(restinio::own_io_context(), std::move(settings), std::size_t(config_.io_threads));
    } catch (const std::exception& e) {
      return Status(StatusCode::kIo, std::string("cannot listen on ") + config_.host + ":" + std::to_string(config_.port) +
                                         ": " + e.what(),
                    "--port");
    }
    std::cerr << "solidtex serve: listening on http://" << config_.host << ":" << config_.port << " (data "
              << store_->describe() << ", " << config_.threads << " workers, queue " << config_.queue << ")" << std::endl;
    if (config_.web_root.empty())
      std::cerr << "solidtex serve: no browser app (--web-root names its directory)" << std::endl;
    else
      std::cerr << "solidtex serve: browser app at http://" << config_.host << ":" << config_.port << "/ (from "
                << config_.web_root << ")" << std::endl;

    int sig = 0;
    sigwait(&signals, &sig);
    std::cerr << "solidtex serve: " << (sig == SIGTERM ? "SIGTERM" : "SIGINT") << ", shutting down" << std::endl;
    stopping_ = true;
    // Running requests get a grace period, then their interrupters fire.
    std::thread watchdog([this] {
      for (int i = 0; i < 50 && pool_->running() + pool_->queued() > 0; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      abort_running_ = true;
    });
    pool_->shutdown();
    watchdog.join();
    running->stop();
    running->wait();
    exemplars_->shutdown();
    std::cerr << "solidtex serve: stopped" << std::endl;
    return Status::ok();
  }

 private:
  void send(const restinio::request_handle_t& req, const HttpRequest& hr, const HttpResponse& resp) {
    metrics_.observe(hr.route.empty() ? "unmatched" : hr.route, hr.method, resp.status,
                     std::chrono::duration<double>(Clock::now() - hr.arrival).count());
    const restinio::http_status_line_t status{restinio::http_status_code_t{std::uint16_t(resp.status)},
                                              reason_phrase(resp.status)};
    // HEAD: the same status and headers as GET, the Content-Length of the body GET would send, no body.
    int64_t head_only = resp.content_length;
    if (head_only < 0 && hr.method == "HEAD") head_only = int64_t(resp.body.size());
    if (head_only >= 0) {
      auto rb = req->create_response<restinio::user_controlled_output_t>(status);
      if (!resp.content_type.empty()) rb.append_header(restinio::http_field::content_type, resp.content_type);
      for (const auto& [k, v] : resp.headers) rb.append_header(k, v);
      rb.set_content_length(std::size_t(head_only));
      rb.done();
      return;
    }
    auto rb = req->create_response(status);
    if (!resp.content_type.empty()) rb.append_header(restinio::http_field::content_type, resp.content_type);
    for (const auto& [k, v] : resp.headers) rb.append_header(k, v);
    rb.set_body(resp.body);
    rb.done();
  }

  HttpResponse error(int status, const std::string& code, const std::string& message, const std::string& field) {
    HttpResponse r;
    r.status = status;
    r.body = error_body(code, message, field);
    return r;
  }

  static constexpr size_t kMaxParts = 16;

  // Splits a multipart/form-data body into named parts.
  Status split_parts(const restinio::request_handle_t& req, HttpRequest& hr) {
    namespace hfp = restinio::http_field_parsers;
    Status st;
    auto result = restinio::multipart_body::enumerate_parts(
        *req,
        [&](restinio::multipart_body::parsed_part_t part) {
          const auto disposition = part.fields.opt_value_of(restinio::http_field::content_disposition);
          if (!disposition) {
            st = Status(StatusCode::kInvalidArgument, "a part has no Content-Disposition", "body");
            return restinio::multipart_body::handling_result_t::terminate_enumeration;
          }
          const auto parsed = hfp::content_disposition_value_t::try_parse(*disposition);
          if (!parsed) {
            st = Status(StatusCode::kInvalidArgument, "a part's Content-Disposition cannot be parsed", "body");
            return restinio::multipart_body::handling_result_t::terminate_enumeration;
          }
          const auto name = hfp::find_first(parsed->parameters, "name");
          if (!name) {
            st = Status(StatusCode::kInvalidArgument, "a part's Content-Disposition has no name", "body");
            return restinio::multipart_body::handling_result_t::terminate_enumeration;
          }
          // No endpoint takes more than six parts; a body of thousands must not cost quadratic work.
          if (hr.parts.size() >= kMaxParts) {
            st = Status(StatusCode::kInvalidArgument, "has more than " + std::to_string(kMaxParts) + " parts", "body");
            return restinio::multipart_body::handling_result_t::terminate_enumeration;
          }
          hr.parts.emplace_back(std::string(name->data(), name->size()), std::string(part.body.data(), part.body.size()));
          return restinio::multipart_body::handling_result_t::continue_enumeration;
        },
        "multipart", "form-data");
    if (!st.is_ok()) return st;
    if (!result) return Status(StatusCode::kInvalidArgument, "the multipart/form-data body cannot be parsed", "body");
    return Status::ok();
  }

  restinio::request_handling_status_t handle(restinio::request_handle_t req) {
    auto hr = std::make_shared<HttpRequest>();
    try {
      hr->method = std::string(req->header().method().c_str());
      hr->path = std::string(req->header().path());
      hr->content_type = media_type(req->header().get_field_or(restinio::http_field::content_type, ""));
      hr->accept = lower(req->header().get_field_or(restinio::http_field::accept, ""));
      hr->range = req->header().get_field_or(restinio::http_field::range, "");
      hr->if_range = req->header().get_field_or(restinio::http_field::if_range, "");
      hr->if_none_match = req->header().get_field_or(restinio::http_field::if_none_match, "");
      std::vector<std::string> allowed;
      const Route* route = match_route(hr->method, hr->path, hr->path_params, allowed);
      if (!route) {
        if (allowed.empty()) {
          send(req, *hr, error(404, "not_found", "no route for " + hr->path, "path"));
        } else {
          HttpResponse r = error(405, "method_not_allowed", hr->method + " is not allowed on " + hr->path, "method");
          std::string allow;
          for (const auto& m : allowed) allow += (allow.empty() ? "" : ", ") + m;
          r.headers.push_back({"Allow", allow});
          send(req, *hr, r);
        }
        return restinio::request_accepted();
      }
      hr->route = route->path;
      if (int64_t(req->body().size()) > config_.max_upload_bytes) {
        send(req, *hr, error(413, "too_large",
                             "the body has " + std::to_string(req->body().size()) + " bytes; the limit is " +
                                 std::to_string(config_.max_upload_bytes) + " (--max-upload-mb)",
                             "body"));
        return restinio::request_accepted();
      }
      try {
        for (const auto& [k, v] : restinio::parse_query<restinio::parse_query_traits::relaxed>(req->header().query()))
          hr->query.emplace_back(std::string(k), std::string(v));
      } catch (const std::exception& e) {
        send(req, *hr, error(400, "invalid_argument", std::string("malformed query string: ") + e.what(), "query"));
        return restinio::request_accepted();
      }
      if (hr->content_type == "multipart/form-data") {
        hr->multipart = true;
        if (Status st = split_parts(req, *hr); !st.is_ok()) {
          send(req, *hr, HttpResponse::error(st));
          return restinio::request_accepted();
        }
      } else {
        hr->body = std::string(req->body());
      }
      registry().add(req->connection_id(), hr->disconnected);
      auto run = [this, req, hr, route] {
        HttpResponse resp;
        try {
          resp = (api_.get()->*(route->handler))(*hr);
        } catch (const std::exception& e) {
          resp = error(500, "internal", std::string("unexpected failure: ") + e.what(), "");
        }
        send(req, *hr, resp);
      };
      if (route->execution == Execution::kInline) {
        run();
      } else if (stopping_.load() || !pool_->try_submit(run)) {
        HttpResponse r = error(503, "resource_exhausted",
                               stopping_.load() ? "the server is shutting down"
                                                : "all " + std::to_string(pool_->workers()) + " workers are busy and " +
                                                      std::to_string(pool_->capacity()) + " requests are waiting",
                               "");
        r.headers.push_back({"Retry-After", "1"});
        send(req, *hr, r);
      }
    } catch (const std::exception& e) {
      send(req, *hr, error(500, "internal", std::string("unexpected failure: ") + e.what(), ""));
    }
    return restinio::request_accepted();
  }

  ServerConfig config_;
  std::unique_ptr<Storage> store_;
  std::unique_ptr<ExemplarService> exemplars_;
  std::unique_ptr<FieldService> fields_;
  std::unique_ptr<VolumeService> volumes_;
  std::unique_ptr<MeshService> meshes_;
  std::unique_ptr<WorkerPool> pool_;
  std::unique_ptr<Api> api_;
  Metrics metrics_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> abort_running_{false};
};

}  // namespace

Status run_server(const ServerConfig& config) {
  SOLIDTEX_RETURN_IF_ERROR(config.validate());
  // Few malloc arenas (glibc makes up to 8 per core, one per thread that allocates at once):
  // freed memory stays in its arena, so each extra arena can hold another request's working
  // memory. One per synthesis worker measured the lowest peaks at no cost in speed (bench_rss).
  mallopt(M_ARENA_MAX, std::max(2, config.threads));
  Server server(config);
  return server.run();
}

}  // namespace solidtex::server
