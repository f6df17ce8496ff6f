// The Foxglove WebSocket server (foxglove_server.hpp), on civetweb; clients' JSON read with
// nlohmann/json (Debian's nlohmann-json3-dev).
#include "foxglove_server.hpp"

#include "../common/web_access.hpp"

#include <civetweb.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <utility>

namespace ssx::foxglove {

struct Server::Client {
  mg_connection* conn = nullptr;
  std::thread thread;
  bool closed = false;  // (under the server's mutex, as all below)
  std::vector<std::string> texts;  // JSON messages to send: the server's information, channels, statuses
  std::map<std::uint32_t, std::size_t> subscriptions;  // the client's id -> channel index
  std::vector<std::uint64_t> sent;  // per channel: the sequence number of the message sent last
  std::uint64_t time_seq = 0;
  web::MessageRate rate;
};

namespace {

using nlohmann::json;

constexpr std::size_t kMaxQueuedTexts = 64;

std::string status(int level, const std::string& message) {
  return json{{"op", "status"}, {"level", level}, {"message", message}}.dump();
}

// an unsigned 32-bit integer in a client's message, into `out`; false when it is none
bool id32(const json& value, std::uint32_t& out) {
  if (!value.is_number_integer() || (!value.is_number_unsigned() && value.get<std::int64_t>() < 0)) return false;
  const auto v = value.get<std::uint64_t>();
  if (v > std::numeric_limits<std::uint32_t>::max()) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}

void putLittle(char* out, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) out[i] = static_cast<char>((value >> (8 * i)) & 0xff);
}

const char* kSubprotocols[] = {Server::kSubprotocol};
mg_websocket_subprotocols kOffered{1, kSubprotocols};

}  // namespace

Server::Server(const std::string& bind, int port, std::string token, int max_clients, std::string name,
               std::vector<Channel> channels)
    : token_(std::move(token)),
      name_(std::move(name)),
      max_clients_(max_clients),
      channels_(std::move(channels)),
      subscribers_(new std::atomic<int>[channels_.size()]),
      slots_(channels_.size()) {
  for (std::size_t i = 0; i < channels_.size(); ++i) subscribers_[i] = 0;
  const auto session = std::chrono::duration_cast<std::chrono::milliseconds>(
                           std::chrono::system_clock::now().time_since_epoch()).count();
  info_ = json{{"op", "serverInfo"},
               {"name", name_},
               {"capabilities", json::array({"time"})},
               {"metadata", json::object()},
               {"sessionId", std::to_string(session)}}
              .dump();
  json advertised = json::array();
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    const Channel& c = channels_[i];
    advertised.push_back({{"id", i + 1},
                          {"topic", c.topic},
                          {"encoding", c.encoding},
                          {"schemaName", c.schema_name},
                          {"schema", c.schema},
                          {"schemaEncoding", c.schema_encoding}});
  }
  advertise_ = json{{"op", "advertise"}, {"channels", advertised}}.dump();

  mg_init_library(0);
  const std::string ports = bind + ":" + std::to_string(port);
  const std::string threads = std::to_string(max_clients + 2);  // a worker per client, and a few to refuse more
  const char* options[] = {"listening_ports", ports.c_str(), "num_threads", threads.c_str(), "request_timeout_ms",
                           "10000", "websocket_timeout_ms", "3600000", "enable_keep_alive", "no", nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };  // no logging to stderr
  ctx_ = mg_start(&callbacks, this, options);
  if (ctx_ == nullptr)
    throw std::runtime_error("cannot listen on " + ports + " (is the port in use? choose another with --foxglove PORT)");
  mg_set_websocket_handler_with_subprotocols(ctx_, "/", &kOffered, &Server::onConnect, &Server::onReady,
                                             &Server::onData, &Server::onClose, this);
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

bool Server::wanted(std::size_t index) const noexcept {
  return index < channels_.size() && subscribers_[index].load(std::memory_order_relaxed) > 0;
}

void Server::publish(std::size_t index, std::uint64_t time_ns, std::string payload) {
  if (index >= channels_.size()) return;
  auto message = std::make_shared<Message>(Message{time_ns, std::move(payload)});
  std::lock_guard lock(mutex_);
  slots_[index].newest = std::move(message);
  ++slots_[index].seq;
  ++counts_.messages_published;
  changed_.notify_all();
}

void Server::publishTime(std::uint64_t time_ns) {
  std::lock_guard lock(mutex_);
  time_ = time_ns;
  ++time_seq_;
  changed_.notify_all();
}

ServerCounts Server::counts() const {
  std::lock_guard lock(mutex_);
  ServerCounts c = counts_;
  c.clients = clients_.size();
  for (const auto& client : clients_) c.messages_skipped += backlog(*client);  // (what waits for a stalled client)
  return c;
}

int Server::onConnect(const mg_connection* conn, void* self) {
  auto& s = *static_cast<Server*>(self);
  const mg_request_info* info = mg_get_request_info(conn);
  const bool foxglove =
      info->acceptedWebSocketSubprotocol != nullptr && std::strcmp(info->acceptedWebSocketSubprotocol, kSubprotocol) == 0;
  std::lock_guard lock(s.mutex_);
  if (s.stopping_ || !foxglove || static_cast<int>(s.clients_.size()) >= s.max_clients_ ||
      (!s.token_.empty() && web::queryValue(info->query_string, "token") != s.token_)) {
    ++s.counts_.clients_refused;
    return 1;  // refused
  }
  auto client = std::make_shared<Client>();
  client->conn = const_cast<mg_connection*>(conn);
  client->sent.assign(s.channels_.size(), 0);
  client->time_seq = s.time_seq_ > 0 ? s.time_seq_ - 1 : 0;  // (the time now, first)
  client->texts = {s.info_, s.advertise_};
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
  web::lowerThisThreadsPriority();
  std::vector<char> frame;
  for (;;) {
    std::vector<std::string> texts;
    std::vector<std::pair<std::uint32_t, std::shared_ptr<const Message>>> messages;
    std::optional<std::uint64_t> time;
    {
      std::unique_lock lock(mutex_);
      auto pending = [&] {
        if (!client->texts.empty() || time_seq_ > client->time_seq) return true;
        for (const auto& [id, channel] : client->subscriptions)
          if (slots_[channel].seq > client->sent[channel]) return true;
        return false;
      };
      changed_.wait(lock, [&] { return client->closed || stopping_ || pending(); });
      if (client->closed || stopping_) return;
      texts.swap(client->texts);
      if (time_seq_ > client->time_seq) time = time_, client->time_seq = time_seq_;
      for (const auto& [id, channel] : client->subscriptions) {
        const Slot& slot = slots_[channel];
        if (slot.seq <= client->sent[channel]) continue;
        counts_.messages_skipped += slot.seq - client->sent[channel] - 1;
        client->sent[channel] = slot.seq;
        messages.emplace_back(id, slot.newest);
      }
    }
    bool ok = true;
    mg_lock_connection(client->conn);
    for (const std::string& t : texts)
      ok = ok && mg_websocket_write(client->conn, MG_WEBSOCKET_OPCODE_TEXT, t.data(), t.size()) > 0;
    if (time) {  // opcode 2, the time (ns)
      char bytes[9] = {2};
      putLittle(bytes + 1, *time, 8);
      ok = ok && mg_websocket_write(client->conn, MG_WEBSOCKET_OPCODE_BINARY, bytes, sizeof bytes) > 0;
    }
    for (const auto& [id, message] : messages) {  // opcode 1, the subscription, the time (ns), the payload
      frame.resize(13 + message->payload.size());
      frame[0] = 1;
      putLittle(frame.data() + 1, id, 4);
      putLittle(frame.data() + 5, message->time, 8);
      std::memcpy(frame.data() + 13, message->payload.data(), message->payload.size());
      ok = ok && mg_websocket_write(client->conn, MG_WEBSOCKET_OPCODE_BINARY, frame.data(), frame.size()) > 0;
    }
    mg_unlock_connection(client->conn);
    if (!ok) return;  // the client went away: onClose ends it
    std::lock_guard lock(mutex_);
    counts_.messages_sent += messages.size();
  }
}

int Server::onData(mg_connection* conn, int opcode, char* data, std::size_t size, void* self) {
  auto& s = *static_cast<Server*>(self);
  auto* client = static_cast<Client*>(mg_get_user_connection_data(conn));
  const int kind = opcode & 0xf;
  if (kind == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if (web::answerPing(conn, opcode, data, size) || client == nullptr) return 1;
  std::lock_guard lock(s.mutex_);
  std::string refused;
  if (!client->rate.allow(kMaxMessagesPerSecond))
    refused = "more than " + std::to_string(kMaxMessagesPerSecond) + " messages a second: dropped";
  else if (kind != MG_WEBSOCKET_OPCODE_TEXT)
    refused = "binary messages (publishing, service calls) are not offered: dropped";
  else if (size > kMaxMessage)
    refused = "a message of " + std::to_string(size) + " bytes, more than " + std::to_string(kMaxMessage) + ": dropped";
  if (refused.empty()) {
    s.handle(*client, std::string(data, size));
  } else {
    ++s.counts_.requests_dropped;
    if (client->texts.size() < kMaxQueuedTexts) client->texts.push_back(status(2, refused));
  }
  s.changed_.notify_all();
  return 1;  // keep the connection
}

void Server::handle(Client& client, const std::string& text) {
  std::string problem;
  const json message = json::parse(text, nullptr, false);
  const std::string op = message.is_object() && message.contains("op") && message["op"].is_string()
                             ? message["op"].get<std::string>()
                             : std::string();
  if (op == "subscribe" && message.contains("subscriptions") && message["subscriptions"].is_array()) {
    for (const json& s : message["subscriptions"]) {
      std::uint32_t id = 0, channel = 0;
      if (!s.is_object() || !s.contains("id") || !s.contains("channelId") || !id32(s["id"], id) ||
          !id32(s["channelId"], channel) || channel == 0 || channel > channels_.size()) {
        problem = "subscribe: each subscription needs an id and the channelId of an advertised channel";
        continue;
      }
      const std::size_t index = channel - 1;
      bool taken = client.subscriptions.count(id) > 0;
      for (const auto& [other, c] : client.subscriptions) taken = taken || c == index;
      if (taken) {
        problem = "subscribe: subscription " + std::to_string(id) + " or channel " + std::to_string(channel) +
                  " is subscribed already";
        continue;
      }
      client.subscriptions[id] = index;
      ++subscribers_[index], ++subscriptions_;
      // the channel's newest message at once (the scene, sent once, comes so)
      client.sent[index] = slots_[index].newest ? slots_[index].seq - 1 : slots_[index].seq;
    }
  } else if (op == "unsubscribe" && message.contains("subscriptionIds") && message["subscriptionIds"].is_array()) {
    for (const json& value : message["subscriptionIds"]) {
      std::uint32_t id = 0;
      if (id32(value, id) && client.subscriptions.count(id) > 0)
        unsubscribe(client, id);
      else
        problem = "unsubscribe: no such subscription";
    }
  } else if (message.is_discarded()) {
    problem = "not JSON: dropped";
  } else {
    problem = "'" + op.substr(0, 64) + "' is not offered (this server offers subscribe and unsubscribe): dropped";
  }
  if (problem.empty()) return;
  ++counts_.requests_dropped;
  if (client.texts.size() < kMaxQueuedTexts) client.texts.push_back(status(2, problem));
}

std::uint64_t Server::backlog(const Client& client) const {
  std::uint64_t n = 0;
  for (const auto& [id, channel] : client.subscriptions) n += slots_[channel].seq - client.sent[channel];
  return n;
}

void Server::unsubscribe(Client& client, std::uint32_t id) {
  const auto it = client.subscriptions.find(id);
  if (it == client.subscriptions.end()) return;
  --subscribers_[it->second], --subscriptions_;
  client.subscriptions.erase(it);
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
        s.counts_.messages_skipped += s.backlog(*client);
        while (!client->subscriptions.empty()) s.unsubscribe(*client, client->subscriptions.begin()->first);
        s.clients_.erase(it);
        break;
      }
    s.changed_.notify_all();
  }
  if (client && client->thread.joinable()) client->thread.join();
}

}  // namespace ssx::foxglove
