// The viewer's server (viewer_server.hpp), on civetweb.
#include "viewer_server.hpp"

#include "../common/web_access.hpp"
#include "frame.hpp"

#include <civetweb.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace ssx::viewer {

struct Server::Client {
  mg_connection* conn = nullptr;
  std::thread thread;
  bool closed = false;  // (under the server's mutex)
  std::uint64_t sent_seq = 0;
  std::uint64_t hello_seq = 0;  // the scene this page has
  std::uint64_t hello_written = 0;  // ... written to its socket
  std::uint64_t first_seq = 0;  // the newest frame when it connected
  std::uint64_t sent = 0;       // frames sent to it
  viewer::FramePacer pacer;     // at most the frames a second the page asked for (none: all)
  web::MessageRate rate;  // the page's messages in the current second
};

std::optional<double> jsonNumber(const std::string& text, const char* key, int index) {
  const std::string quoted = std::string("\"") + key + "\":";
  auto at = text.find(quoted);
  if (at == std::string::npos) return std::nullopt;
  at += quoted.size();
  if (index >= 0) {
    if (at >= text.size() || text[at] != '[') return std::nullopt;
    ++at;
    for (int i = 0; i < index; ++i) {
      at = text.find(',', at);
      if (at == std::string::npos) return std::nullopt;
      ++at;
    }
  }
  const char* begin = text.c_str() + at;
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(v)) return std::nullopt;
  return v;
}

Server::Server(const std::string& bind, int port, std::string token, int max_clients, std::vector<Asset> assets,
               std::string hello, MessageHandler on_message)
    : token_(std::move(token)),
      hello_(std::move(hello)),
      max_clients_(max_clients),
      assets_(std::move(assets)),
      on_message_(std::move(on_message)) {
  mg_init_library(0);
  const std::string ports = bind + ":" + std::to_string(port);
  // a worker thread per connection: every client that may be connected, and a few for the page's files
  const std::string threads = std::to_string(max_clients + 4);
  const char* options[] = {"listening_ports", ports.c_str(), "num_threads", threads.c_str(),
                           "request_timeout_ms", "10000", "websocket_timeout_ms", "3600000",
                           "enable_keep_alive", "no", nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };  // no logging to stderr
  ctx_ = mg_start(&callbacks, this, options);
  if (ctx_ == nullptr)
    throw std::runtime_error("cannot listen on " + ports + " (is the port in use? choose another with --view PORT)");
  mg_set_request_handler(ctx_, "/", &Server::onRequest, this);
  mg_set_websocket_handler(ctx_, "/ws", &Server::onConnect, &Server::onReady, &Server::onData, &Server::onClose, this);
  mg_server_port listening[1]{};
  if (mg_get_server_ports(ctx_, 1, listening) >= 1) port_ = listening[0].port;
}

Server::~Server() { stop(); }

void Server::stop() {
  if (ctx_ == nullptr) return;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    changed_.notify_all();
  }
  mg_stop(ctx_);  // closes every connection: onClose joins each sender
  ctx_ = nullptr;
}

void Server::publish(std::vector<std::uint8_t>& frame) {
  std::lock_guard lock(mutex_);
  // the frame goes into the spare buffer (when no page is still sending from it), whose bytes come back
  std::shared_ptr<std::vector<std::uint8_t>> fresh =
      spare_ && spare_.use_count() == 1 ? std::move(spare_) : std::make_shared<std::vector<std::uint8_t>>();
  fresh->swap(frame);
  spare_ = std::move(newest_);
  newest_ = std::move(fresh);
  ++newest_seq_;
  ++counts_.frames_published;
  changed_.notify_all();
}

ServerCounts Server::counts() const {
  std::lock_guard lock(mutex_);
  ServerCounts c = counts_;
  c.clients = clients_.size();
  // a page skipped what was published while it was connected and not sent to it
  for (const auto& client : clients_) c.frames_skipped += newest_seq_ - client->first_seq - client->sent;
  return c;
}

int Server::onRequest(mg_connection* conn, void* self) {
  auto& s = *static_cast<Server*>(self);
  const mg_request_info* info = mg_get_request_info(conn);
  if (std::strcmp(info->request_method, "GET") != 0) {
    mg_send_http_error(conn, 405, "%s", "only GET");
    return 405;
  }
  // only the viewer's own files, by exact name: nothing else is reachable
  const std::string uri = info->local_uri != nullptr ? info->local_uri : "";
  for (const Asset& a : s.assets_) {
    if (uri != a.path) continue;
    if (!s.token_.empty() && std::strcmp(a.path, "/") == 0 && web::queryValue(info->query_string, "token") != s.token_) {
      mg_send_http_error(conn, 403, "%s", "this viewer needs the token printed when the run started (?token=...)");
      return 403;
    }
    mg_printf(conn,
              "HTTP/1.1 200 OK\r\nContent-Type: %s\r\nContent-Length: %zu\r\nCache-Control: no-cache\r\n"
              "Connection: close\r\n\r\n",
              a.content_type, a.size);
    mg_write(conn, a.data, a.size);
    return 200;
  }
  mg_send_http_error(conn, 404, "%s", "not a file of the viewer");
  return 404;
}

int Server::onConnect(const mg_connection* conn, void* self) {
  auto& s = *static_cast<Server*>(self);
  const mg_request_info* info = mg_get_request_info(conn);
  std::lock_guard lock(s.mutex_);
  if (s.stopping_ || static_cast<int>(s.clients_.size()) >= s.max_clients_ ||
      (!s.token_.empty() && web::queryValue(info->query_string, "token") != s.token_)) {
    ++s.counts_.clients_refused;
    return 1;  // refused
  }
  auto client = std::make_shared<Client>();
  client->conn = const_cast<mg_connection*>(conn);
  client->first_seq = client->sent_seq = s.newest_seq_;
  s.clients_.push_back(client);
  mg_set_user_connection_data(conn, client.get());
  return 0;
}

void Server::onReady(mg_connection* conn, void* self) {
  auto& s = *static_cast<Server*>(self);
  std::shared_ptr<Client> client;
  {
    std::lock_guard lock(s.mutex_);
    for (const auto& c : s.clients_)
      if (c->conn == conn) client = c;
  }
  if (!client) return;
  client->thread = std::thread([&s, client] { s.sendLoop(client); });
}

void Server::sendLoop(const std::shared_ptr<Client>& client) {
  for (;;) {
    std::shared_ptr<const std::vector<std::uint8_t>> frame;
    std::string hello;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] {
        return client->closed || stopping_ || newest_seq_ > client->sent_seq || hello_seq_ > client->hello_seq;
      });
      if (client->closed || stopping_) return;
      if (hello_seq_ > client->hello_seq) {  // the scene first, before any frame of it
        client->hello_seq = hello_seq_;
        hello = hello_;
      } else {
        const auto now = std::chrono::steady_clock::now();
        if (!client->pacer.due(now)) {  // at the page's rate: the newest frame when its time comes
          changed_.wait_until(lock, client->pacer.next(),
                              [&] { return client->closed || stopping_ || hello_seq_ > client->hello_seq; });
          continue;
        }
        client->pacer.sent(now);
        client->sent_seq = newest_seq_;
        frame = newest_;
      }
    }
    mg_lock_connection(client->conn);
    const int written = frame ? mg_websocket_write(client->conn, MG_WEBSOCKET_OPCODE_BINARY,
                                                   reinterpret_cast<const char*>(frame->data()), frame->size())
                              : mg_websocket_write(client->conn, MG_WEBSOCKET_OPCODE_TEXT, hello.data(), hello.size());
    mg_unlock_connection(client->conn);
    if (written <= 0) return;  // the page went away: onClose ends it
    std::lock_guard lock(mutex_);
    if (frame) ++counts_.frames_sent, ++client->sent;
    if (!frame) client->hello_written = client->hello_seq, changed_.notify_all();
  }
}

void Server::setHello(std::string hello) {
  std::lock_guard lock(mutex_);
  hello_ = std::move(hello);
  ++hello_seq_;
  changed_.notify_all();
}

void Server::farewell(std::string message, std::chrono::milliseconds wait) {
  std::unique_lock lock(mutex_);
  hello_ = std::move(message);
  const std::uint64_t seq = ++hello_seq_;
  changed_.notify_all();
  changed_.wait_for(lock, wait, [&] {
    for (const auto& c : clients_)
      if (!c->closed && c->hello_written < seq) return false;
    return true;
  });
}

int Server::onData(mg_connection* conn, int opcode, char* data, std::size_t size, void* self) {
  auto& s = *static_cast<Server*>(self);
  auto* client = static_cast<Client*>(mg_get_user_connection_data(conn));
  const int kind = opcode & 0xf;
  if (kind == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if (web::answerPing(conn, opcode, data, size)) return 1;
  bool take = client != nullptr && kind == MG_WEBSOCKET_OPCODE_TEXT && size <= kMaxMessage;
  if (take) take = client->rate.allow(kMaxMessagesPerSecond);
  std::string text(take ? data : "", take ? size : 0);
  if (take && text.find(R"("type":"hello")") != std::string::npos) {
    if (const auto rate = jsonNumber(text, "rate_hz")) {
      take = *rate > 0 && *rate <= 240;
      std::lock_guard lock(s.mutex_);
      if (take) client->pacer = viewer::FramePacer(std::chrono::duration<double>(1.0 / *rate));
    }
  }
  if (take) take = s.on_message_ && s.on_message_(text);
  if (!take) {
    std::lock_guard lock(s.mutex_);
    ++s.counts_.messages_dropped;
  }
  return 1;  // keep the connection
}

void Server::onClose(const mg_connection* conn, void* self) {
  auto& s = *static_cast<Server*>(self);
  std::shared_ptr<Client> client;
  {
    std::lock_guard lock(s.mutex_);
    for (auto it = s.clients_.begin(); it != s.clients_.end(); ++it)
      if ((*it)->conn == conn) {
        client = *it;
        client->closed = true;
        s.counts_.frames_skipped += s.newest_seq_ - client->first_seq - client->sent;
        s.clients_.erase(it);
        break;
      }
    s.changed_.notify_all();
  }
  if (client && client->thread.joinable()) client->thread.join();
}

}  // namespace ssx::viewer
