#pragma once
// A server for Foxglove's WebSocket protocol (subprotocol foxglove.websocket.v1, as its published
// specification describes it), on civetweb: Foxglove, Lichtblick or any client of the protocol
// connects to ws://ADDR:PORT/, gets the server's information and its channels (topic, encoding,
// schema), subscribes to the channels it wants and receives their messages, stamped with the
// simulation's time (the `time` capability: binary time messages carry it too).
//
// Never slows the simulation: publish() puts a message into its channel's newest-message slot
// under a mutex and returns; each client has a thread of its own that sends, for each channel it
// subscribed to, the newest message it has not sent yet. A slow or stalled client skips messages
// (counted) and holds up nobody. Bounded: at most max_clients clients; a client's text message
// larger than kMaxMessage bytes, more than kMaxMessagesPerSecond a second, not JSON, or asking what
// is not offered (an unknown channel, a subscription id in use) is answered with a status message
// and counted as dropped. Clients cannot publish, call services or set parameters (none offered).
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

struct mg_context;
struct mg_connection;

namespace ssx::foxglove {

/// A channel offered to clients. Its id is its index in the server's list plus one.
struct Channel {
  std::string topic;
  std::string encoding;  ///< "json"
  std::string schema_name;
  std::string schema;
  std::string schema_encoding;  ///< "jsonschema"
};

/// What the server counts.
struct ServerCounts {
  std::uint64_t messages_published = 0;
  std::uint64_t messages_sent = 0;      ///< over every client
  std::uint64_t messages_skipped = 0;   ///< newer messages of their channel replaced them before a client took them
  std::uint64_t requests_dropped = 0;   ///< a client's messages: too large, too many, or not understood
  std::uint64_t clients_refused = 0;    ///< beyond max_clients, without the token, or without the subprotocol
  std::uint64_t clients = 0;            ///< connected now
};

class Server {
 public:
  static constexpr const char* kSubprotocol = "foxglove.websocket.v1";
  static constexpr std::size_t kMaxMessage = 64 * 1024;
  static constexpr int kMaxMessagesPerSecond = 100;

  /// Listens on `bind`:`port` (0: a free port, see port()). `token`: when not empty, a client must
  /// connect with `?token=` it. `name` is the server's name in its information message.
  /// Throws std::runtime_error, naming the address, when it cannot listen (a port in use).
  Server(const std::string& bind, int port, std::string token, int max_clients, std::string name,
         std::vector<Channel> channels);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The port listened on.
  int port() const noexcept { return port_; }
  /// Whether some client subscribed to channel `index` (0-based): what nobody wants need not be made.
  bool wanted(std::size_t index) const noexcept;
  /// Whether some client subscribed to any channel.
  bool anyWanted() const noexcept { return subscriptions_.load(std::memory_order_relaxed) > 0; }
  /// Hands a message of channel `index` (0-based), stamped `time_ns`, to the clients subscribed
  /// to it, and returns at once.
  void publish(std::size_t index, std::uint64_t time_ns, std::string payload);
  /// The simulation's time, sent to every client (a binary time message).
  void publishTime(std::uint64_t time_ns);
  /// What was counted so far.
  ServerCounts counts() const;
  /// Stops listening, closes every client and joins their threads.
  void stop();

 private:
  struct Client;
  struct Message {
    std::uint64_t time = 0;
    std::string payload;
  };
  struct Slot {
    std::shared_ptr<const Message> newest;
    std::uint64_t seq = 0;
  };
  static int onConnect(const mg_connection* conn, void* self);
  static void onReady(mg_connection* conn, void* self);
  static int onData(mg_connection* conn, int opcode, char* data, std::size_t size, void* self);
  static void onClose(const mg_connection* conn, void* self);
  void sendLoop(const std::shared_ptr<Client>& client);
  void handle(Client& client, const std::string& text);  // (under mutex_)
  void unsubscribe(Client& client, std::uint32_t id);    // (under mutex_)
  std::uint64_t backlog(const Client& client) const;     // messages not sent to it yet (under mutex_)

  mg_context* ctx_ = nullptr;
  int port_ = 0;
  std::string token_, name_, info_, advertise_;
  int max_clients_;
  std::vector<Channel> channels_;
  std::unique_ptr<std::atomic<int>[]> subscribers_;  // per channel, over every client
  std::atomic<int> subscriptions_{0};
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Slot> slots_;
  std::uint64_t time_ = 0, time_seq_ = 0;
  std::list<std::shared_ptr<Client>> clients_;
  ServerCounts counts_;
  bool stopping_ = false;
};

}  // namespace ssx::foxglove
