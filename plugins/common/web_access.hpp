#pragma once
// What the extensions that listen on a socket share (the viewer, the Foxglove server, both on
// civetweb): the address checked before anything is bound, the token an address other than
// loopback needs, a client's message rate, answering a WebSocket ping, and the priority of the
// threads that send.
#include <civetweb.h>

#include <ssx/descriptor.hpp>

#include <arpa/inet.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstring>
#include <random>
#include <string>

namespace ssx::web {

/// The parameter `bind` is one IPv4 address or localhost (civetweb would take "+" or a list of
/// ports in it and listen wider than asked); throws the parameter's error, before anything is bound.
inline void checkBindAddress(const Descriptor& params) {
  const std::string bind = params.get<std::string>("bind");
  in_addr address{};
  if (bind != "localhost" && inet_pton(AF_INET, bind.c_str(), &address) != 1)
    throw params.error("bind must be one IPv4 address (127.0.0.1, 0.0.0.0 for every interface, or an interface's "
                       "address) or localhost, got '" + bind + "'");
}

inline bool isLoopback(const std::string& bind) { return bind == "127.0.0.1" || bind == "localhost"; }

/// The token a client must give (`?token=`) when the server listens on `bind`: none on loopback,
/// else 32 random hexadecimal digits.
inline std::string accessToken(const std::string& bind) {
  std::string token;
  if (isLoopback(bind)) return token;
  std::random_device random;
  const char* digits = "0123456789abcdef";
  for (int i = 0; i < 32; ++i) token += digits[random() % 16];
  return token;
}

/// The value of `key` in a request's query string; empty when absent.
inline std::string queryValue(const char* query, const char* key) {
  if (query == nullptr) return {};
  char value[256];
  const int n = mg_get_var(query, std::strlen(query), key, value, sizeof value);
  return n < 0 ? std::string() : std::string(value, static_cast<std::size_t>(n));
}

/// A client's messages in the current second of the wall clock.
struct MessageRate {
  std::chrono::steady_clock::time_point window = std::chrono::steady_clock::now();
  int messages = 0;
  /// Counts one more message; false when it is more than `most` in its second.
  bool allow(int most) {
    const auto now = std::chrono::steady_clock::now();
    if (now - window > std::chrono::seconds(1)) window = now, messages = 0;
    return ++messages <= most;
  }
};

/// A ping answered with its pong, as the protocol asks (clients' keep-alive). True when `opcode`
/// was a ping or a pong, which need nothing more.
inline bool answerPing(mg_connection* conn, int opcode, const char* data, std::size_t size) {
  const int kind = opcode & 0xf;
  if (kind == MG_WEBSOCKET_OPCODE_PING && size <= 125) {
    mg_lock_connection(conn);
    mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_PONG, data, size);
    mg_unlock_connection(conn);
  }
  return kind == MG_WEBSOCKET_OPCODE_PING || kind == MG_WEBSOCKET_OPCODE_PONG;
}

/// The calling thread only (Linux's nice value is per thread) at the lowest priority: the stepping
/// threads take a core first.
inline void lowerThisThreadsPriority() {
  (void)setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), 19);
}

}  // namespace ssx::web
