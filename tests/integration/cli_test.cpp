// The `ssx` command, run as a child process: exit codes, messages, files, Ctrl-C.
#include <ssx/ssx.hpp>

#include "record/mcap_reader.hpp"
#include "record/mcap_writer.hpp"
#include "render_util.hpp"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using Catch::Contains;

#if defined(__SANITIZE_ADDRESS__)
#define SSX_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SSX_UNDER_ASAN 1
#endif
#endif
#ifndef SSX_UNDER_ASAN
#define SSX_UNDER_ASAN 0
#endif

extern char** environ;

namespace {

const std::string kCli = SSX_CLI_PATH;
const fs::path kData = SSX_TEST_DATA_DIR;
const fs::path kExamples = SSX_EXAMPLES_DIR;

struct Result {
  int status = -1;
  std::string out, err;
};

// runs ssx with `args` (or the program args[0] names by an absolute path); `extra_env` entries are
// added to the child's environment only;
// `on_err` sees stderr as it grows and may signal the child
Result run(std::vector<std::string> args, std::vector<std::string> extra_env = {},
           const std::function<void(pid_t, const std::string&)>& on_err = {}) {
  int out_pipe[2], err_pipe[2];
  REQUIRE(pipe(out_pipe) == 0);
  REQUIRE(pipe(err_pipe) == 0);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string s(*e);
    if (s.rfind("SSX_PLUGIN_PATH=", 0) != 0) env_strings.push_back(s);
  }
  for (auto& e : extra_env) env_strings.push_back(e);
  if (args.empty() || args[0].front() != '/') args.insert(args.begin(), kCli);  // (or a program by its path)
  std::vector<char*> argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    dup2(out_pipe[1], 1);
    dup2(err_pipe[1], 2);
    close(out_pipe[0]);
    close(err_pipe[0]);
    execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  close(out_pipe[1]);
  close(err_pipe[1]);
  Result r;
  pollfd fds[2] = {{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}};
  int open_fds = 2;
  while (open_fds > 0) {
    if (poll(fds, 2, -1) < 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || (fds[i].revents & (POLLIN | POLLHUP)) == 0) continue;
      char buf[4096];
      const ssize_t n = read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
        continue;
      }
      (i == 0 ? r.out : r.err).append(buf, static_cast<std::size_t>(n));
      if (i == 1 && on_err) on_err(pid, r.err);
    }
  }
  int status = 0;
  waitpid(pid, &status, 0);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

}  // namespace

TEST_CASE("ssx --version and --help", "[cli]") {
  const Result v = run({"--version"});
  CHECK(v.status == 0);
  CHECK_THAT(v.out, Contains(std::string("ssx ") + SSX_VERSION_STRING));
  const Result h = run({"run", "--help"});
  CHECK(h.status == 0);
  CHECK_THAT(h.out, Contains("--realtime") && Contains("--plugin-path") && Contains("--stats-csv"));
}

TEST_CASE("ssx validate: 0 for a good scene, 2 with the diagnostics for a broken one", "[cli]") {
  const Result good = run({"validate", (kExamples / "scenes" / "hover_swarm.xml").string()});
  CHECK(good.status == 0);
  CHECK_THAT(good.out, Contains("ok: 32 artifacts"));
  const Result bad =
      run({"validate", (kData / "invalid" / "negative_mass.xml").string(), "--plugin-path", SSX_TEST_PLUGIN_DIR});
  CHECK(bad.status == 2);
  CHECK_THAT(bad.err, Contains("parts/negative_mass.xml:3: error: physic node 'body': mass must be positive"));
}

TEST_CASE("ssx validate, run and sweep: inputs beyond --max-input-mb are refused with exit 2, naming the file",
          "[cli]") {
  // a scene of 4 KiB (a long comment), its artifact file beside the examples'
  const std::string scene = (fs::current_path() / "padded_scene.xml").string();
  std::ofstream(scene) << "<scene><!--" << std::string(4096, '-') << "--><type name=\"b\" file=\""
                       << (kExamples / "artifacts" / "box.xml").string() << "\"/><artifact name=\"b\" type=\"b\"/></scene>\n";
  const Result small = run({"validate", scene, "--max-input-mb", "0.002"});
  CHECK(small.status == 2);
  CHECK_THAT(small.err, Contains("padded_scene.xml: error: cannot read it: larger than the limit on input files (0.002 MiB; it has at least 0.00"));
  CHECK(run({"validate", scene, "--max-input-mb", "1"}).status == 0);
  CHECK(run({"run", scene, "--steps", "1", "--quiet", "--max-input-mb", "0.002"}).status == 2);
  CHECK(run({"validate", scene, "--max-input-mb", "0"}).status == 2);  // no limit below a KiB
  // a state to load is an input too
  const Result state = run({"run", scene, "--steps", "1", "--quiet", "--load-state", "/dev/zero"});
  CHECK(state.status == 2);
  CHECK_THAT(state.err, Contains("--load-state /dev/zero: cannot read it: not a regular file"));
}

TEST_CASE("ssx: memory running out while loading is a message and status 1, not an abort", "[cli]") {
  // a million boxes fit the estimate of any machine this runs on, not an address space of 600 MB
  const fs::path scene = fs::current_path() / "million_boxes.xml";
  std::ofstream(scene) << "<scene><type name=\"b\" file=\"" << (kExamples / "artifacts" / "box.xml").string()
                       << "\"/><swarm type=\"b\" count=\"1000000\" name=\"b{i}\"/></scene>\n";
  const Result r = run({"/bin/sh", "-c", "ulimit -v 600000 && exec \"$0\" validate \"$1\"", kCli, scene.string()});
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Contains("ssx: error: out of memory"));
}

TEST_CASE("ssx run: numbers are decimal and in range, with the range said plainly, one seed range everywhere",
          "[cli]") {
  const std::string scene = (kExamples / "scenes" / "hover_swarm.xml").string();
  const auto err = [&](const std::string& option, const std::string& value) {
    const Result r = run({"run", scene, "--fast", "--quiet", option, value});
    CHECK(r.status == 2);
    return r.err;
  };
  // seeds beyond 2^64 - 1 were taken as 2^64 - 1, so different seeds gave one run
  CHECK_THAT(err("--seed", "18446744073709551616"),
             Contains("--seed: must be a whole number in decimal from 0 to 18446744073709551615, got '18446744073709551616'"));
  CHECK_THAT(err("--seed", "99999999999999999999999"), Contains("from 0 to 18446744073709551615"));
  CHECK_THAT(err("--seed", "-1"), Contains("got '-1'"));
  CHECK_THAT(err("--steps", "0x10"), Contains("--steps: must be a whole number in decimal"));
  CHECK_THAT(err("--steps", "1e3"), Contains("got '1e3'"));
  CHECK_THAT(err("--threads", "5000"), Contains("--threads: must be from 0 to 1024, got 5000"));
  // bounds as a person writes them (they were printed with 300 digits)
  const std::string duration = err("--duration", "1e10");
  CHECK_THAT(duration, Contains("--duration: must be above 0 and at most 1e+09, got 1e10"));
  CHECK(duration.size() < 200);
  CHECK_THAT(err("--duration", "nan"), Contains("must be a decimal number above 0"));
  CHECK_THAT(err("--realtime", "1e9"), Contains("--realtime: must be from 0.001 to 1e+06"));
  CHECK(run({"run", scene, "--steps", "1", "--quiet", "--seed", "18446744073709551615"}).status == 0);
  fs::remove("hover_swarm_poses.csv");
}

TEST_CASE("ssx validate lists a scene's problems by line, whatever order they were found in", "[cli]") {
  // the environment is read before the swarms: its error was found second and printed first
  const fs::path scene = fs::current_path() / "unsorted.xml";
  std::ofstream(scene) << "<scene>\n  <swarm type=\"b\" count=\"2\" layout=\"hexagonal\"/>\n  <type name=\"b\" file=\""
                       << (kExamples / "artifacts" / "box.xml").string() << "\"/>\n  <environment timestep=\"-1\"/>\n</scene>\n";
  const Result r = run({"validate", scene.string()});
  CHECK(r.status == 2);
  const auto second = r.err.find("unsorted.xml:2: error:");
  const auto fourth = r.err.find("unsorted.xml:4: error:");
  REQUIRE(second != std::string::npos);
  REQUIRE(fourth != std::string::npos);
  CHECK(second < fourth);
  CHECK_THAT(r.err, Contains("2 error(s); nothing was run"));
}

TEST_CASE("ssx run: a scene's own outputs go into ssx-out/<scene>/ or --out DIR, never the working directory unasked",
          "[cli]") {
  const std::string logged = (kExamples / "scenes" / "hover_swarm.xml").string();  // a logger, file="hover_swarm_poses.csv"
  fs::remove_all("ssx-out");
  fs::remove_all("chosen");
  fs::remove("hover_swarm_poses.csv");
  REQUIRE(run({"run", logged, "--steps", "50", "--fast", "--quiet"}).status == 0);
  CHECK(fs::is_regular_file("ssx-out/hover_swarm/hover_swarm_poses.csv"));
  REQUIRE(run({"run", logged, "--steps", "50", "--fast", "--quiet", "--out", "chosen"}).status == 0);
  CHECK(fs::is_regular_file("chosen/hover_swarm_poses.csv"));
  CHECK_FALSE(fs::exists("hover_swarm_poses.csv"));
  // a scene that writes nothing makes no directory; the command's own outputs stay where they are named
  const std::string quiet_scene = (kExamples / "scenes" / "quad_hover.xml").string();
  fs::remove("own.png");
  REQUIRE(run({"run", quiet_scene, "--steps", "20", "--fast", "--quiet", "--snapshot", "own.png"}).status == 0);
  CHECK(fs::is_regular_file("own.png"));
  CHECK_FALSE(fs::exists("ssx-out/quad_hover"));
}

TEST_CASE("ssx validate --print: the scene with every default, which validates and prints the same again", "[cli]") {
  const Result printed = run({"validate", (kExamples / "scenes" / "hover_swarm.xml").string(), "--print"});
  REQUIRE(printed.status == 0);
  CHECK_THAT(printed.out, Contains("<physics engine=\"ode\" gravity=\"0 0 -9.81\" substeps=\"1\"") &&
                              Contains("<swarm type=") && Contains("layout=\"grid\" xyz="));
  const fs::path copy = fs::temp_directory_path() / "ssx_cli_printed_scene.xml";
  std::ofstream(copy) << printed.out;
  const Result again = run({"validate", copy.string(), "--print"});
  CHECK(again.status == 0);
  CHECK(again.out == printed.out);
}

TEST_CASE("ssx run never writes its inputs, nor two outputs onto one file, and checks before anything is written",
          "[cli][outputs]") {
  const fs::path dir = fs::absolute("outputs_case");
  fs::remove_all(dir);
  fs::create_directories(dir / "sub");
  const fs::path scene = dir / "s.xml";
  std::ofstream(scene) << R"(<scene><environment timestep="0.01"/>
    <type name="ball" file=")" << (kData / "valid" / "ball.xml").string() << R"("/>
    <artifact name="b" type="ball" xyz="0 0 1"/>
    <extension name="log" plugin="csv_logger" file=")" << (dir / "log.csv").string() << R"("/></scene>)";
  const auto text = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  const std::string before = text(scene);
  // the state over the scene itself, by another spelling: refused, the scene untouched, no log begun
  const Result over = run({"run", scene.string(), "--fast", "--steps", "5", "--save-state",
                           (dir / "sub" / ".." / "s.xml").string()});
  CHECK(over.status == 2);
  CHECK_THAT(over.err, Contains("--save-state") && Contains("which this run reads"));
  CHECK(text(scene) == before);
  CHECK_FALSE(fs::exists(dir / "log.csv"));
  // over the artifact file the scene reads, and onto the logger's file: refused too
  CHECK(run({"run", scene.string(), "--fast", "--steps", "5", "--save-state", (kData / "valid" / "ball.xml").string()})
            .status == 2);
  const Result twice = run({"run", scene.string(), "--fast", "--steps", "5", "--stats-csv", (dir / "log.csv").string()});
  CHECK(twice.status == 2);
  CHECK_THAT(twice.err, Contains("which this run writes already"));
  // a symbolic link is not replaced: it is refused and stays a link
  fs::create_symlink(dir / "target.state", dir / "link.state");
  const Result link = run({"run", scene.string(), "--fast", "--steps", "5", "--save-state", (dir / "link.state").string()});
  CHECK(link.status == 2);
  CHECK(fs::is_symlink(dir / "link.state"));
  // a good run writes both
  CHECK(run({"run", scene.string(), "--fast", "--steps", "5", "--save-state", (dir / "ok.state").string()}).status == 0);
  CHECK(fs::exists(dir / "ok.state"));
  CHECK(fs::exists(dir / "log.csv"));
  fs::remove_all(dir);
}

TEST_CASE("ssx validate and ssx plugins name the engines, --physics chooses one and checks the scene for it",
          "[cli][cross_engine]") {
  CHECK_THAT(run({"plugins"}).out, Contains("physics engines: ode, bullet") && Contains("render engines: null"));
  const std::string scene = (kExamples / "scenes" / "hover_swarm.xml").string();
  CHECK_THAT(run({"validate", scene}).out, Contains("physics engine ode (available: ode, bullet)"));
  CHECK_THAT(run({"validate", scene, "--physics", "bullet"}).out, Contains("physics engine bullet"));
  CHECK(run({"validate", scene, "--physics", "physx"}).status == 2);
  // an ODE option in a scene run on Bullet is an error at its line, and nothing runs
  const std::string ode_only = (kData / "valid" / "ode_options.xml").string();
  const Result refused = run({"run", ode_only, "--physics", "bullet", "--fast", "--steps", "10"});
  CHECK(refused.status == 2);
  CHECK_THAT(refused.err, Contains("ode_options.xml:3: error: <physics>: attribute 'sor' is an option of the ode "
                                   "engine, and the engine is 'bullet' (chosen with --physics)"));
  CHECK(run({"run", ode_only, "--fast", "--steps", "10"}).status == 0);
  const Result bullet = run({"run", scene, "--physics", "bullet", "--fast", "--steps", "100"});
  CHECK(bullet.status == 0);
  CHECK_THAT(bullet.out, Contains("steps 100, simulated 0.200 s"));
}

TEST_CASE("bad arguments exit with 2", "[cli]") {
  CHECK(run({"run", "/no/such/scene.xml"}).status == 2);
  CHECK(run({"run", (kExamples / "scenes" / "hover_swarm.xml").string(), "--fast", "--realtime"}).status == 2);
  CHECK(run({"fly"}).status == 2);
  CHECK(run({}).status == 2);
}

TEST_CASE("ssx run --fast --steps writes the timing CSV and the summary", "[cli]") {
  fs::remove("cli_stats.csv");
  const Result r = run({"run", (kExamples / "scenes" / "hover_swarm.xml").string(), "--fast", "--steps", "100",
                        "--stats-csv", "cli_stats.csv", "--threads", "2", "--seed", "3"});
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Contains("steps 100, simulated 0.200 s"));
  std::ifstream csv("cli_stats.csv");
  int lines = 0;
  for (std::string line; std::getline(csv, line);) ++lines;
  CHECK(lines == 101);
}

TEST_CASE("a plugin failing while running exits with 1 naming artifact and plugin", "[cli]") {
  const Result r =
      run({"run", (kData / "valid" / "bomb.xml").string(), "--fast", "--plugin-path", SSX_TEST_PLUGIN_DIR});
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Contains("step 5: artifact 'victim', driver 'bomb': exploded as asked"));
}

TEST_CASE("SSX_PLUGIN_PATH is read by the command", "[cli]") {
  const std::string scene = (kData / "valid" / "warnings.xml").string();
  CHECK(run({"validate", scene}).status == 2);  // test_good is not on any default path
  CHECK(run({"validate", scene}, {std::string("SSX_PLUGIN_PATH=/nowhere:") + SSX_TEST_PLUGIN_DIR}).status == 0);
}

TEST_CASE("ssx plugins lists libraries, classes and failing checks", "[cli]") {
  const Result builtin = run({"plugins"});
  CHECK(builtin.status == 0);
  CHECK_THAT(builtin.out,
             Contains("libssx_hover.so: ok") && Contains("  driver hover") && Contains("  extension csv_logger"));
  const Result tests = run({"plugins", "--plugin-path", SSX_TEST_PLUGIN_DIR});
  CHECK(tests.status == 2);
  CHECK_THAT(tests.out, Contains("libssx_test_wrong_abi.so: FAILS: plugin ABI version 999"));
  CHECK_THAT(tests.out, Contains("  sensor counter"));
}

TEST_CASE("ssx plugins survives a library that crashes while loading, and lists the others", "[cli]") {
  const Result r = run({"plugins", "--plugin-path", SSX_TEST_CRASHING_PLUGIN_DIR, "--plugin-path", SSX_TEST_PLUGIN_DIR});
  CHECK(r.status == 2);
#if SSX_UNDER_ASAN
  // AddressSanitizer catches the SIGSEGV itself, reports it and ends the child its own way
  // (an abort or an exit status, as ASAN_OPTIONS say)
  CHECK_THAT(r.out, Contains("libssx_test_crashing.so: FAILS: "));
#else
  CHECK_THAT(r.out, Contains("libssx_test_crashing.so: FAILS: crashed while being loaded (signal 11"));
#endif
  // it went on: the libraries after it are listed, and the built-in ones
  CHECK_THAT(r.out, Contains("libssx_test_good.so: ok") && Contains("libssx_hover.so: ok"));
  // --params looks past it too
  const Result params = run({"plugins", "--plugin-path", SSX_TEST_CRASHING_PLUGIN_DIR, "--params", "hover"});
  CHECK(params.status == 0);
  CHECK_THAT(params.out, Contains("| `kp` |"));
}

TEST_CASE("Ctrl-C stops a real-time run cleanly: summary printed, files closed", "[cli]") {
  fs::remove("hover_swarm_poses.csv");
  fs::remove_all("ssx-out");
  bool sent = false;
  const Result r = run({"run", (kExamples / "scenes" / "hover_swarm.xml").string(), "--duration", "1000"}, {},
                       [&sent](pid_t pid, const std::string& err) {
                         // interrupt once the run has started
                         if (!sent && err.find("artifacts,") != std::string::npos) {
                           kill(pid, SIGINT);
                           sent = true;
                         }
                       });
  REQUIRE(sent);
  CHECK(r.status == 130);  // 128 + SIGINT, as a shell reports it
  CHECK_THAT(r.err, Contains("ssx: interrupted at t = "));
  CHECK_THAT(r.out, Contains("step time ms"));
  // the logger's file, in the run's output directory (not the working directory), was flushed and
  // closed by its shutdown: complete lines only
  CHECK_FALSE(fs::exists("hover_swarm_poses.csv"));
  std::ifstream csv("ssx-out/hover_swarm/hover_swarm_poses.csv");
  std::string content((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
  REQUIRE_FALSE(content.empty());
  CHECK(content.back() == '\n');
}

TEST_CASE("ssx run: SIGTERM stops a run cleanly with 143, and the state asked for is saved", "[cli]") {
  bool sent = false;
  const fs::path state = fs::absolute("sigterm.state");
  fs::remove(state);
  const Result r = run({"run", (kExamples / "scenes" / "hover_swarm.xml").string(), "--duration", "1000",
                        "--save-state", state.string()},
                       {}, [&sent](pid_t pid, const std::string& err) {
                         if (!sent && err.find("artifacts,") != std::string::npos) {
                           kill(pid, SIGTERM);
                           sent = true;
                         }
                       });
  REQUIRE(sent);
  CHECK(r.status == 143);
  CHECK(fs::exists(state));
}

TEST_CASE("ssx run: an unknown render engine is refused before the scene's logger opens its file", "[cli]") {
  fs::remove("hover_swarm_poses.csv");
  const Result r = run({"run", (kExamples / "scenes" / "hover_swarm.xml").string(), "--render", "foo", "--fast",
                        "--steps", "5"});
  CHECK(r.status == 2);
  CHECK_THAT(r.err, Contains("render engine 'foo'") && Contains("available: null"));
  CHECK_FALSE(fs::exists("hover_swarm_poses.csv"));
}

TEST_CASE("ssx run: a duration below a nanosecond or not a number is refused, not run without end", "[cli]") {
  const std::string scene = (kExamples / "scenes" / "hover_swarm.xml").string();
  for (const char* d : {"1e-12", "nan"}) {
    INFO(d);
    const Result r = run({"run", scene, "--fast", "--duration", d});
    CHECK(r.status == 2);
  }
}

TEST_CASE("ssx run: a log file that cannot be written fails the run with status 1 naming the file", "[cli][csv]") {
  std::ofstream("full.xml") << R"(<scene duration="0.2"><environment timestep="0.01"/>
    <type name="ball" file=")" << (kData / "valid" / "ball.xml").string() << R"("/>
    <artifact name="b" type="ball" xyz="0 0 1"/>
    <extension name="log" plugin="csv_logger" file="/dev/full" flush_s="0.05"/></scene>)";
  // a device is refused as an output unless streams into one are allowed
  const Result refused = run({"run", "full.xml", "--fast"});
  CHECK(refused.status == 2);
  CHECK_THAT(refused.err, Contains("parameter 'file' '/dev/full' is not a regular file") &&
                              Contains("--allow-special-outputs"));
  const Result r = run({"run", "full.xml", "--fast", "--allow-special-outputs"});
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Contains("cannot write '/dev/full'") && Contains("No space left on device"));
  CHECK_FALSE(Contains("step time ms").match(r.out));  // no summary of a failed run
}

TEST_CASE("ssx run --rt-priority: out of range or with --fast refused, refused before anything is written "
          "where it is not permitted, else used", "[cli]") {
  const std::string scene = (kExamples / "scenes" / "hover_swarm.xml").string();
  CHECK(run({"run", scene, "--rt-priority", "0", "--steps", "5"}).status == 2);
  CHECK(run({"run", scene, "--rt-priority", "100", "--steps", "5"}).status == 2);
  CHECK(run({"run", scene, "--rt-priority", "5", "--fast", "--steps", "5"}).status == 2);
  const fs::path dir = "cli_rt_priority";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path csv = dir / "stats.csv";
  const Result r = run({"run", scene, "--rt-priority", "5", "--steps", "20", "--stats-csv", csv.string()});
  if (ssx::realtimePriorityProblem(5).empty()) {
    CHECK(r.status == 0);
    CHECK_THAT(r.out, Contains("steps 20"));
  } else {
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Contains("--rt-priority 5: SCHED_FIFO priority 5 is not permitted here"));
    CHECK_FALSE(fs::exists(csv));
  }
  fs::remove_all(dir);
}

TEST_CASE("ssx run: a bare --realtime means factor 1, a given factor is used", "[cli]") {
  const std::string scene = (kExamples / "scenes" / "hover_swarm.xml").string();
  const Result plain = run({"run", scene, "--realtime", "--steps", "50"});
  CHECK(plain.status == 0);
  CHECK_THAT(plain.err, Contains("real time x1,") || Contains("real time x1\n"));
  const Result doubled = run({"run", scene, "--steps", "50", "--realtime", "4"});
  CHECK(doubled.status == 0);
  CHECK_THAT(doubled.err, Contains("real time x4"));
  CHECK_THAT(doubled.out, Contains("steps 50"));
}

TEST_CASE("ssx run --record, inspect and replay: a run kept, looked at, drawn again and re-simulated bit for bit",
          "[cli][record]") {
  const fs::path dir = fs::temp_directory_path() / ("ssx_record_cli_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (kExamples / "scenes" / "quad_hover.xml").string();
  const std::string rec = (dir / "hover.mcap").string();
  const Result ran = run({"run", scene, "--steps", "1000", "--fast", "--record", rec, "--out", (dir / "out").string()});
  REQUIRE(ran.status == 0);
  CHECK_THAT(ran.out, Catch::Contains("recording " + rec + ": 50 samples of 3 bodies (0 dropped), 1 saved states"));
  const Result inspected = run({"inspect", rec, "--json"});
  CHECK(inspected.status == 0);
  CHECK_THAT(inspected.out, Catch::Contains("\"complete\":true") && Catch::Contains("\"/ssx/poses\":50") &&
                                Catch::Contains("\"first_time_ns\":40000000,\"last_time_ns\":2000000000"));
  const Result drawn = run({"replay", rec, "--snapshot", (dir / "replay.png").string(), "--from", "1"});
  CHECK(drawn.status == 0);
  CHECK_THAT(drawn.out, Catch::Contains("replayed 26 samples of 3 bodies (1.000 s to 2.000 s)"));
  CHECK(fs::file_size(dir / "replay.png") > 1000);
  // the last second's path behind each robot: the same picture with dots added where they flew
  const Result trails = run({"replay", rec, "--snapshot", (dir / "trails.png").string(), "--from", "1", "--trails", "1"});
  CHECK(trails.status == 0);
  const ssx::Image plain = ssx::test::readPng(dir / "replay.png"), dotted = ssx::test::readPng(dir / "trails.png");
  REQUIRE((plain.width > 0 && plain.width == dotted.width && plain.height == dotted.height));
  std::size_t changed_pixels = 0;
  for (std::size_t i = 0; i + 2 < plain.rgb.size(); i += 3)
    changed_pixels += plain.rgb[i] != dotted.rgb[i] || plain.rgb[i + 1] != dotted.rgb[i + 1] || plain.rgb[i + 2] != dotted.rgb[i + 2];
  CHECK(changed_pixels > 200);
  CHECK(changed_pixels < plain.rgb.size() / 3 / 10);  // dots, not another picture
  // at half speed each sample is drawn twice: 51 frames for the second from 1 s to 2 s
  const Result slow = run({"replay", rec, "--frames", (dir / "slow").string(), "--from", "1", "--speed", "0.5"});
  CHECK(slow.status == 0);
  CHECK_THAT(slow.out, Catch::Contains("replayed 51 frames of 3 bodies (1.000 s to 2.000 s)"));
  const Result again = run({"replay", rec, "--resimulate-from", "0"});
  CHECK(again.status == 0);
  CHECK_THAT(again.err, !Catch::Contains("was recorded by ssx"));
  {
    // the same recording said to be of another version: the replay says so before it draws
    const fs::path other = dir / "other_version.mcap";
    ssx::detail::rewriteMcap(ssx::detail::readMcap(rec), other, {}, [](const std::string& name, auto& values) {
      if (name == "ssx") values["version"] = "0.0.1";
    });
    const Result old_version = run({"replay", other.string(), "--snapshot", (dir / "old.png").string()});
    CHECK(old_version.status == 0);
    CHECK_THAT(old_version.err, Catch::Contains("was recorded by ssx 0.0.1, this is ssx " SSX_VERSION_STRING));
  }
  CHECK_THAT(again.out, Catch::Contains("49 recorded samples compared, every one equal to the recording bit for bit"));
  // a changed gain: the same start, then another flight
  const Result changed =
      run({"replay", rec, "--resimulate-from", "0", "--set", "artifact[name=mk]/driver@position_kp=1 1 1"});
  CHECK(changed.status == 0);
  CHECK_THAT(changed.out, Catch::Contains("recorded samples compared, ") && Catch::Contains("the first difference at"));
  // nothing is written over the recording, or over the scene
  const Result over = run({"replay", rec, "--snapshot", rec});
  CHECK(over.status == 2);
  CHECK_THAT(over.err, Catch::Contains("would write over the recording being replayed"));
  // a page plays the recording: not together with pictures or a re-simulation
  const Result view_and_picture = run({"replay", rec, "--view", "0", "--snapshot", (dir / "v.png").string()});
  CHECK(view_and_picture.status == 2);
  CHECK_THAT(view_and_picture.err, Catch::Contains("--view plays the recording on a page"));
  CHECK_FALSE(fs::exists(dir / "v.png"));
  CHECK(run({"run", scene, "--steps", "10", "--fast", "--record", scene}).status == 2);
  // --complete goes through the one output check: not the recording itself, not a FIFO
  const Result onto_itself = run({"inspect", rec, "--complete", rec});
  CHECK(onto_itself.status == 2);
  CHECK_THAT(onto_itself.err, Catch::Contains("which this run reads"));
  REQUIRE(mkfifo((dir / "pipe").c_str(), 0600) == 0);
  const Result onto_fifo = run({"inspect", rec, "--complete", (dir / "pipe").string()});
  CHECK(onto_fifo.status == 2);
  CHECK(run({"inspect", rec, "--complete", (dir / "copy.mcap").string()}).status == 0);
  CHECK(fs::file_size(dir / "copy.mcap") > 1000);
  CHECK(run({"inspect", rec}).status == 0);
  // a file that is not a recording: a message naming it, status 2
  const Result foreign = run({"inspect", scene});
  CHECK(foreign.status == 2);
  CHECK_THAT(foreign.err, Catch::Contains(scene + ": byte 0: not an MCAP file"));
  fs::remove_all(dir);
}

TEST_CASE("ssx run --switch-physics: the run goes on on the other engine, and its recording re-simulates bit for bit",
          "[cli][record][switch_physics]") {
  const fs::path dir = fs::temp_directory_path() / ("ssx_switch_cli_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (kExamples / "scenes" / "quad_hover.xml").string();
  const std::string rec = (dir / "switched.mcap").string();
  // an engine that is not there, or no time: refused before anything is written
  for (const char* bad : {"1:mujoco", "bullet", "-1:bullet", "x:ode"}) {
    const Result refused = run({"run", scene, "--steps", "10", "--fast", "--switch-physics", bad, "--record", rec});
    CHECK(refused.status == 2);
    CHECK_THAT(refused.err, Catch::Contains("--switch-physics") && Catch::Contains("SECONDS:ENGINE"));
    CHECK_FALSE(fs::exists(rec));
  }
  const Result ran = run({"run", scene, "--steps", "1500", "--fast", "--switch-physics", "1:bullet", "--switch-physics",
                          "2:ode", "--record", rec, "--record-states", "0.5", "--out", (dir / "out").string()});
  REQUIRE(ran.status == 0);
  CHECK_THAT(ran.out, Catch::Contains("physics: ode, then bullet from 1 s, then ode from 2 s"));
  CHECK_THAT(ran.out, Catch::Contains(", crashed 0"));
  const Result inspected = run({"inspect", rec});
  CHECK_THAT(inspected.out, Catch::Contains("physics: ode to bullet at 1.000 s\nphysics: bullet to ode at 2.000 s"));
  const Result as_json = run({"inspect", rec, "--json"});
  CHECK_THAT(as_json.out, Catch::Contains("\"physics_switches\":[{\"time_ns\":1000000000,\"from\":\"ode\",\"to\":\"bullet\"},"));
  // from the start, from a state saved on ODE just before the first switch (1 s), from one saved
  // on Bullet (1.5 s): the switches are made again at their times, and every sample is as recorded
  for (const char* from : {"0", "1.2", "1.7"}) {
    INFO("from " << from);
    const Result again = run({"replay", rec, "--resimulate-from", from});
    CHECK(again.status == 0);
    CHECK_THAT(again.out, Catch::Contains("every one equal to the recording bit for bit"));
  }
  fs::remove_all(dir);
}

TEST_CASE("ssx validate and ssx run agree on the whole invalid corpus: the same first error, exit 2, nothing run",
          "[cli]") {
  const auto firstError = [](const std::string& err) {
    const auto at = err.find(": error: ");
    if (at == std::string::npos) return std::string("(no error)");
    const auto begin = err.rfind('\n', at);
    return err.substr(begin == std::string::npos ? 0 : begin + 1, err.find('\n', at) - (begin == std::string::npos ? 0 : begin + 1));
  };
  int files = 0;
  for (const auto& entry : fs::directory_iterator(kData / "invalid")) {
    if (entry.path().extension() != ".xml") continue;
    ++files;
    INFO(entry.path().filename().string());
    const Result validate = run({"validate", entry.path().string(), "--plugin-path", SSX_TEST_PLUGIN_DIR});
    const Result ran =
        run({"run", entry.path().string(), "--steps", "1", "--fast", "--quiet", "--plugin-path", SSX_TEST_PLUGIN_DIR});
    CHECK(validate.status == 2);
    CHECK(ran.status == 2);
    CHECK(firstError(validate.err) == firstError(ran.err));
    CHECK(firstError(validate.err) != "(no error)");
  }
  CHECK(files >= 80);
  CHECK_FALSE(fs::exists("marker_ran.txt"));
  CHECK_FALSE(fs::exists("ssx-out"));  // (where a run would have written)
}

TEST_CASE("ssx: empty output names, options without the one they need, and empty windows are errors", "[cli]") {
  const std::string scene = (kExamples / "scenes" / "quad_hover.xml").string();
  for (const auto& option : {"--record", "--save-state", "--stats-csv", "--snapshot", "--video", "--frames", "--out"}) {
    INFO(option);
    const Result r = run({"run", scene, "--steps", "1", "--fast", "--quiet", option, ""});
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Contains("an empty name: give a file or directory name"));
  }
  const Result rate = run({"run", scene, "--steps", "1", "--fast", "--quiet", "--record-rate", "10"});
  CHECK(rate.status == 2);
  CHECK_THAT(rate.err, Contains("--record-rate requires --record"));
  CHECK(run({"run", scene, "--steps", "1", "--fast", "--quiet", "--record-states", "1"}).status == 2);
  CHECK(run({"run", scene, "--steps", "1", "--fast", "--quiet", "--record-channels", "timing"}).status == 2);
  const fs::path dir = fs::current_path() / "cli_windows";
  fs::create_directories(dir);
  const std::string rec = (dir / "r.mcap").string();
  const Result tiny = run({"run", scene, "--duration", "1", "--fast", "--quiet", "--record", rec, "--record-rate", "1e-17"});
  CHECK(tiny.status == 2);
  CHECK_THAT(tiny.err, Contains("is below 1e-6 Hz"));
  REQUIRE(run({"run", scene, "--duration", "1", "--fast", "--quiet", "--record", rec}).status == 0);
  const Result backwards = run({"replay", rec, "--from", "3", "--to", "1", "--snapshot", (dir / "w.png").string()});
  CHECK(backwards.status == 2);
  CHECK_THAT(backwards.err, Contains("an empty window (--to comes before --from)"));
  const Result beyond = run({"replay", rec, "--from", "5", "--snapshot", (dir / "w.png").string()});
  CHECK(beyond.status == 2);
  CHECK_THAT(beyond.err, Contains("nothing to draw from 5.000 s: the recording's samples run from 0.040 s to 1.000 s"));
  CHECK_FALSE(fs::exists(dir / "w.png"));
  for (const auto& bind : {"127.0.0.1+", "127.0.0.1:80,0.0.0.0", "256.0.0.1", "1.2.3", "", "example.org"}) {
    INFO(bind);
    const Result r = run({"run", scene, "--steps", "1", "--fast", "--quiet", "--view", "0", "--view-bind", bind});
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Contains("must be one IPv4 address"));
    const Result f = run({"run", scene, "--steps", "1", "--fast", "--quiet", "--foxglove", "0", "--foxglove-bind", bind});
    CHECK(f.status == 2);
    CHECK_THAT(f.err, Contains("must be one IPv4 address"));
  }
  // the viewer and the Foxglove server both on Foxglove's default port: said before anything listens
  const Result both = run({"run", scene, "--steps", "1", "--fast", "--quiet", "--view", "--foxglove"});
  CHECK(both.status == 2);
  CHECK_THAT(both.err, Contains("--view and --foxglove both on port 8765: give one of them another port"));
  CHECK(run({"run", scene, "--steps", "1", "--fast", "--quiet", "--foxglove-bind", "127.0.0.1"}).status == 2);
}

TEST_CASE("ssx replay and inspect: a hard link to the recording is the recording, a FIFO is refused, not waited on",
          "[cli]") {
  const std::string scene = (kExamples / "scenes" / "quad_hover.xml").string();
  const fs::path dir = fs::current_path() / "cli_links";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path rec = dir / "r.mcap";
  REQUIRE(run({"run", scene, "--duration", "0.5", "--fast", "--quiet", "--record", rec.string()}).status == 0);
  const auto before = fs::file_size(rec);
  fs::create_hard_link(rec, dir / "hard.mcap");
  for (const auto& option : {"--snapshot", "--video"}) {
    const Result r = run({"replay", rec.string(), option, (dir / "hard.mcap").string()});
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Contains("would write over the recording being replayed"));
  }
  const Result resim = run({"replay", rec.string(), "--resimulate-from", "0", "--record", (dir / "hard.mcap").string()});
  CHECK(resim.status == 2);
  CHECK(fs::file_size(rec) == before);
  const Result into = run({"replay", rec.string(), "--frames", dir.string()});
  CHECK(into.status == 2);
  CHECK_THAT(into.err, Contains("which this run reads"));
  const fs::path fifo = dir / "f.mcap";
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  for (const auto& command : {std::vector<std::string>{"inspect", fifo.string()},
                              std::vector<std::string>{"replay", fifo.string(), "--snapshot", (dir / "x.png").string()},
                              std::vector<std::string>{"replay", fifo.string(), "--view", "0"}}) {
    const Result r = run(command);
    CHECK(r.status == 2);
    CHECK_THAT(r.err, Contains("not a regular file"));
  }
}

TEST_CASE("ssx run --frames-from/--frames-until: frames only in that window, the run bitwise the same", "[cli][render]") {
  const fs::path dir = fs::current_path() / "cli_frames_window";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (kExamples / "scenes" / "quad_hover.xml").string();
  const std::string out = (dir / "out").string();
  REQUIRE(run({"run", scene, "--steps", "750", "--fast", "--quiet", "--out", out, "--save-state",
               (dir / "plain.state").string()})
              .status == 0);
  const Result windowed = run({"run", scene, "--steps", "750", "--fast", "--out", out, "--frames",
                               (dir / "frames").string(), "--frames-from", "0.5", "--frames-until", "1", "--save-state",
                               (dir / "windowed.state").string()});
  REQUIRE(windowed.status == 0);
  // 25 frames per simulated second from 0.5 s to 1 s: 0.5, 0.54, ..., 0.98 s
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir / "frames")) files += e.path().extension() == ".png" ? 1 : 0;
  CHECK(files == 13);
  CHECK_THAT(windowed.out, Contains(": 13 frames in " + (dir / "frames").string()));
  auto bytes = [](const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  CHECK(bytes(dir / "plain.state") == bytes(dir / "windowed.state"));
  CHECK_FALSE(bytes(dir / "plain.state").empty());
  const Result backwards = run({"run", scene, "--steps", "1", "--fast", "--quiet", "--snapshot", (dir / "s.png").string(),
                                "--frames-from", "1", "--frames-until", "0.5"});
  CHECK(backwards.status == 2);
  CHECK_THAT(backwards.err, Contains("an empty window"));
  const Result nothing = run({"run", scene, "--steps", "1", "--fast", "--quiet", "--frames-from", "1"});
  CHECK(nothing.status == 2);
  CHECK_THAT(nothing.err, Contains("the scene draws no frames"));
}

TEST_CASE("ssx run --view: the view is no part of the run's state, so its recording re-simulates without it",
          "[cli][record]") {
  const fs::path dir = fs::current_path() / "cli_view_record";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = (kExamples / "scenes" / "quad_hover.xml").string();
  const std::string rec = (dir / "viewed.mcap").string();
  REQUIRE(run({"run", scene, "--steps", "600", "--fast", "--quiet", "--view", "0", "--record", rec, "--record-states",
               "0.5", "--out", (dir / "out").string()})
              .status == 0);
  const Result again = run({"replay", rec, "--resimulate-from", "0.6"});
  CHECK(again.status == 0);
  CHECK_THAT(again.out, Contains("every one equal to the recording bit for bit"));
}
