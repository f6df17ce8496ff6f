// `ssx plugins`: every library on the search path inspected in a child process (a library's
// static initialisers run when it is opened, and one that crashes must not take ssx down).
#include "plugins_command.hpp"

#include "common.hpp"

#include <ssx/ssx.hpp>

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

extern char** environ;

namespace ssx::cli {

namespace fs = std::filesystem;

namespace {

// What one library reports, printed by a child process (`ssx plugins --inspect FILE`): with
// `params_of`, that class's parameter table (exit 0, or 4 when the library has no such class);
// else the library's lines of the listing (exit 0 when it passes its checks, 3 when not).
constexpr int kExitNoSuchClass = 4, kExitLibraryFails = 3;


struct Child {
  int status = -1;  ///< exit status, or -signal
  bool timed_out = false;
  std::string out;
};

// runs this program again with `args`, collecting its standard output; killed after `timeout_s`
Child runSelf(const std::vector<std::string>& args, double timeout_s) {
  Child c;
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::vector<std::string> argv_strings = {"/proc/self/exe"};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  pid_t pid = -1;
  const int failed = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (failed != 0) {
    close(fds[0]);
    throw std::runtime_error(std::string("cannot start a child to inspect a plugin: ") + std::strerror(failed));
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      kill(pid, SIGKILL);
      c.timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) continue;
    const ssize_t n = read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    c.out.append(buffer, static_cast<std::size_t>(n));
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  c.status = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? -WTERMSIG(status) : -1;
  return c;
}

// why a child that inspected `file` did not report
std::string childProblem(const Child& c) {
  if (c.timed_out) return "FAILS: did not finish loading within 10 s (a static initialiser that waits or loops?)";
  if (c.status < 0)
    return "FAILS: crashed while being loaded (signal " + std::to_string(-c.status) + ", " + strsignal(-c.status) +
           "): in a static initialiser of the library or of one it pulls in";
  return "FAILS: its inspection ended with status " + std::to_string(c.status);
}

// Each library is opened in a child process of its own: one that crashes or hangs while loading
// (static initialisers run before any check can) is reported, and this process loads none.
}  // namespace

int inspectOne(const std::string& file, const std::string& params_of) {
  const ssx::PluginLibraryInfo lib = ssx::ClassLoader::inspect(file);
  if (!params_of.empty()) {
    for (const auto& c : lib.classes) {
      if (!lib.ok || c.name != params_of) continue;
      std::cout << ssx::toString(c.kind) << " '" << c.name << "' (" << lib.path.string() << ")"
                << (c.doc.empty() ? "" : ": " + c.doc) << "\n\n"
                << c.parameter_table;
      return 0;
    }
    return kExitNoSuchClass;
  }
  std::cout << lib.path.string() << ": " << (lib.ok ? "ok" : "FAILS: " + lib.problem) << '\n';
  for (const auto& c : lib.classes)
    std::cout << "  " << ssx::toString(c.kind) << ' ' << c.name << (c.doc.empty() ? "" : ": " + c.doc) << '\n';
  return lib.ok ? 0 : kExitLibraryFails;
}

int commandPlugins(const std::vector<std::string>& plugin_path, const std::string& params_of) {
  ssx::ClassLoader loader;
  for (const auto& dir : pluginPath(plugin_path)) loader.addSearchDirectory(dir);
  loader.addSearchDirectory(ssx::ClassLoader::installedPluginDirectory());
  std::vector<fs::path> files;
  for (const auto& dir : loader.searchPath()) {
    std::error_code ec;
    std::vector<fs::path> here;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().extension() == ".so") here.push_back(e.path());
    std::sort(here.begin(), here.end());
    files.insert(files.end(), here.begin(), here.end());
  }
  constexpr double kTimeout = 10.0;
  // a physics engine's settings: the attributes of <physics engine="NAME"> besides the common ones
  if (const ssx::PhysicEngineClass* engine = ssx::findPhysicEngine(params_of); engine != nullptr) {
    std::cout << "physics engine '" << engine->name << "': " << engine->doc << "\n\n"
              << ssx::parameterTable(engine->settings);
    return 0;
  }
  if (!params_of.empty()) {
    // one class's declared parameters, as the Markdown table the docs hold
    for (const auto& f : files) {
      const Child c = runSelf({"plugins", "--inspect", f.string(), "--params", params_of}, kTimeout);
      if (c.status != 0) continue;
      std::cout << c.out;
      return 0;
    }
    std::cerr << "ssx: error: no plugin class '" << params_of << "' on the search path (ssx plugins lists them)\n";
    return kExitBadInput;
  }
  int bad = 0;
  std::cout << "physics engines: " << joined(ssx::physicEngineNames()) << '\n'
            << "render engines: " << joined(ssx::renderEngineNames()) << '\n';
  for (const auto& dir : loader.searchPath()) std::cout << "search: " << dir.string() << '\n';
  for (const auto& f : files) {
    const Child c = runSelf({"plugins", "--inspect", f.string()}, kTimeout);
    if (c.status == 0 || c.status == kExitLibraryFails) {
      std::cout << c.out;
      bad += c.status == 0 ? 0 : 1;
    } else {
      std::cout << f.string() << ": " << childProblem(c) << '\n';
      ++bad;
    }
    std::cout.flush();
  }
  return bad == 0 ? 0 : kExitBadInput;
}


}  // namespace ssx::cli
