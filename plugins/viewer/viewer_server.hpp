#pragma once
// The viewer's HTTP and WebSocket server (civetweb): serves the page and its scripts from memory
// and streams frames to every page connected at /ws.
//
// Never slows the simulation: publish() swaps a frame into the newest-frame slot under a mutex (no
// copy: the buffer of an earlier frame no page holds any more comes back) and returns; each client has a thread of its own that sends the newest frame it has not sent yet, so
// a slow or stalled page skips frames (counted) and holds up nobody. A page may ask for fewer
// frames: {"type":"hello","rate_hz":R} (0 < R <= 240) sends it at most R a second. Bounded: at most max_clients
// pages; messages from a page larger than kMaxMessage bytes, more than kMaxMessagesPerSecond a
// second, or not understood are dropped and counted.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

struct mg_context;
struct mg_connection;

namespace ssx::viewer {

/// The number after `"key":` in a page's JSON message (or, with `index`, the index-th number of
/// the array after it); nothing when missing or not a finite number.
std::optional<double> jsonNumber(const std::string& text, const char* key, int index = -1);

/// A file the server serves.
struct Asset {
  const char* path;          ///< "/", "/viewer.js", ...
  const char* content_type;  ///< "text/html; charset=utf-8", ...
  const char* data;
  std::size_t size;
};

/// What the server counts.
struct ServerCounts {
  std::uint64_t frames_published = 0;
  std::uint64_t frames_sent = 0;     ///< over every client
  std::uint64_t frames_skipped = 0;  ///< newer frames replaced them before a client took them
  std::uint64_t messages_dropped = 0;  ///< too large, too many, or not understood
  std::uint64_t clients_refused = 0;   ///< beyond max_clients, or without the token
  std::uint64_t clients = 0;           ///< connected now
};

class Server {
 public:
  static constexpr std::size_t kMaxMessage = 4096;
  static constexpr int kMaxMessagesPerSecond = 200;

  /// What a page's text message asks; returns false when it is not understood (counted as dropped).
  using MessageHandler = std::function<bool(const std::string& text)>;

  /// Listens on `bind`:`port` (0: a free port, see port()). `token`: when not empty, a page must
  /// connect with `?token=` it. `hello` is sent to every page as it connects (the scene).
  /// Throws std::runtime_error, naming the address, when it cannot listen (a port in use).
  Server(const std::string& bind, int port, std::string token, int max_clients, std::vector<Asset> assets,
         std::string hello, MessageHandler on_message);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// The port listened on.
  int port() const noexcept { return port_; }
  /// Hands a frame (binary) to every client and returns at once. Takes the bytes, not a copy:
  /// `frame` comes back holding an earlier frame's buffer (any content) to build the next one in.
  void publish(std::vector<std::uint8_t>& frame);
  /// Replaces the message every page gets first (the scene), and sends it to the pages connected.
  void setHello(std::string hello);
  /// The last message every page gets (the run's end): sent to the pages connected, waiting up to
  /// `wait` for them to have it, before stop() closes them.
  void farewell(std::string message, std::chrono::milliseconds wait);
  /// What was counted so far.
  ServerCounts counts() const;
  /// Stops listening, closes every client and joins their threads.
  void stop();

 private:
  struct Client;
  static int onConnect(const mg_connection* conn, void* self);
  static void onReady(mg_connection* conn, void* self);
  static int onData(mg_connection* conn, int opcode, char* data, std::size_t size, void* self);
  static void onClose(const mg_connection* conn, void* self);
  static int onRequest(mg_connection* conn, void* self);
  void sendLoop(const std::shared_ptr<Client>& client);

  mg_context* ctx_ = nullptr;
  int port_ = 0;
  std::string token_, hello_;
  int max_clients_;
  std::vector<Asset> assets_;
  MessageHandler on_message_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<std::vector<std::uint8_t>> newest_, spare_;  // (spare_: the frame before, maybe still being sent)
  std::uint64_t newest_seq_ = 0;
  std::uint64_t hello_seq_ = 1;
  std::list<std::shared_ptr<Client>> clients_;
  ServerCounts counts_;
  bool stopping_ = false;
};

}  // namespace ssx::viewer
