// csv_logger: an extension that writes the poses and velocities of chosen artifacts to a CSV file
// at a rate in simulated time.
//
// Parameters: kParameters below, or `ssx plugins --params csv_logger`.
//
// Columns: time_s,artifact,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz (world frame, SI units). With
// bodies="all", one row per body of each artifact: its root's named as the artifact, each joined
// child's as "artifact/node" (the pose of the node the body begins at); with artifacts="*", the
// joined children of static-rooted articulations (a door, an arm on a table) too. With joints="true"
// (bodies="all"), two more columns, joint_position,joint_velocity: the joint joining the row's body
// to its parent, a hinge's (rad, rad/s) or a slider's (m, m/s); empty for a body joined otherwise.
#include <ssx/environment.hpp>
#include <ssx/plugin_abi.hpp>
#include <ssx/run_files.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <utility>
#include <vector>

namespace ssx::plugins {

class CsvLogger final : public SimulationExtension {
 public:
  static constexpr const char* kDoc = "writes poses and velocities of chosen artifacts to a CSV file";
  static constexpr ssx_plugin_param kParameters[] = {
      param::required(param::output(
          "file", "", "path of the CSV file (relative: in the run's output directory, ssx run --out; else the working directory)")),
      param::text("artifacts", "*", "artifact names separated by spaces, or * for every artifact with a dynamic root"),
      param::choice("bodies", "root", "root all",
                    "root: one row per artifact (its first root); all: one per body, joined children as artifact/node"),
      param::real("rate_hz", "0", "Hz", param::nonNegative() & param::atMost(1e9),
                  "rows per artifact per simulated second; 0 writes one every step"),
      param::real("flush_s", "1", "s", param::positive() & param::atMost(1e9),
                  "simulated time between flushes to the file (and at the end of the run)"),
      param::flag("joints", "false",
                  "bodies=all: also each body's joint position and velocity (a hinge's rad and rad/s, a slider's m "
                  "and m/s; empty for a body joined otherwise)"),
  };

  // what is logged exists before anything is opened
  static void validate(const Descriptor& params, const PluginContext& context) {
    // (the file itself is checked by the loader, with the run's other files: SSX_PARAM_OUTPUT)
    (void)context.environment->selectArtifacts(params, "artifacts", "log");
    if (params.get<bool>("joints") && params.get<std::string>("bodies") != "all")
      throw params.errorAt("joints", "joints=\"true\" logs the joints of an artifact's bodies: give bodies=\"all\" too");
  }

  ~CsvLogger() override { close(); }

  void init(Environment& env, const Descriptor& params) override {
    path_ = params.get<std::string>("file");
    names_ = params.get<std::string>("artifacts");
    const double rate = params.get<double>("rate_hz");
    period_ = rate > 0 ? std::max(env.timestep(), toNanoseconds(1.0 / rate)) : env.timestep();
    next_ = period_;  // rows at period, 2 period, ... of simulated time
    flush_period_ = toNanoseconds(params.get<double>("flush_s"));
    next_flush_ = flush_period_;
    joints_ = params.get<bool>("joints");
    resolve(env, params);
    try {
      file_ = openOutputFile(path_);  // (locked while written: a second run writing it is refused)
    } catch (const Error& e) {
      throw params.error(e.what());
    }
    check(std::fputs(joints_ ? "time_s,artifact,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,joint_position,joint_velocity\n"
                             : "time_s,artifact,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n",
                     file_) >= 0);
  }

  void afterStep(Environment& env) override {
    if (env.time() >= next_flush_) {
      next_flush_ += flush_period_;
      if (next_flush_ <= env.time()) next_flush_ = env.time() + flush_period_;
      check(std::fflush(file_) == 0);
    }
    if (env.time() < next_) return;
    next_ += period_;
    if (next_ <= env.time()) next_ = env.time() + period_;
    const double t = toSeconds(env.time());
    for (const Row& row : rows_) {
      const BodyState s = row.node != nullptr ? row.node->state() : row.artifact->state();
      const Vec3& p = s.pose.position;
      const Quat& q = s.pose.orientation;
      const Vec3& v = s.linear_velocity;
      const Vec3& w = s.angular_velocity;
      const int written = std::fprintf(file_, "%.9g,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", t,
                   row.label.c_str(), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(), v.z(), w.x(),
                   w.y(), w.z());
      check(written > 0);
      if (!joints_) {
        check(std::fputc('\n', file_) != EOF);
      } else if (row.node != nullptr && row.node->joint().hasPosition()) {
        check(std::fprintf(file_, ",%.9g,%.9g\n", row.node->jointPosition(), row.node->jointVelocity()) > 0);
      } else {
        check(std::fputs(",,\n", file_) >= 0);
      }
    }
  }

  // the last rows reach the file, or the run fails saying why
  void shutdown(Environment&) override {
    if (file_ == nullptr) return;
    const bool flushed = std::fflush(file_) == 0;
    const int error = errno;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!flushed || !closed) fail(flushed ? errno : error);
  }

  // rows and flushes go on at the times they would have been
  void saveState(StateWriter& out) const override {
    out.write(next_);
    out.write(next_flush_);
  }
  void loadState(StateReader& in) override {
    in.read(next_);
    in.read(next_flush_);
  }

 private:
  // every artifact exists when extensions are initialised
  // a CSV field: quoted when it holds a comma, a quote or a line break (RFC 4180)
  static std::string field(const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string out = "\"";
    for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
  }

  void resolve(Environment& env, const Descriptor& params) {
    const bool all = params.get<std::string>("bodies") == "all";
    const std::vector<Artifact*> named = env.selectArtifacts(params, "artifacts", "log");
    std::vector<const Artifact*> chosen(named.begin(), named.end());
    if (all && names_ == "*") {
      // every body: a static-rooted articulation's (a door, an arm on a table) too, without its root
      chosen.clear();
      for (std::size_t i = 0; i < env.artifactCount(); ++i) {
        const Artifact& a = std::as_const(env).artifact(i);
        bool moves = false;
        for (std::size_t k = 0; k < a.nodeCount() && !moves; ++k) moves = !a.nodeAt(k).isStatic();
        if (moves) chosen.push_back(&a);
      }
    }
    for (const Artifact* a : chosen) {
      if (!(all && names_ == "*" && a->root().isStatic())) rows_.push_back({a, nullptr, field(a->name())});
      if (!all) continue;
      for (std::size_t k = 0; k < a->nodeCount(); ++k) {
        const PhysicNode& n = a->nodeAt(k);
        const bool another_root = n.parent() == nullptr && &n != &a->root() && !n.isStatic();
        if (another_root || n.joint().isBody()) rows_.push_back({a, &n, field(a->name() + "/" + n.name())});
      }
    }
  }
  // a write that fails (a full disk, a removed device) stops the run naming the file
  void check(bool ok) {
    if (ok) return;
    const int error = errno;
    close();  // reported once, here, not again when the run stops
    fail(error);
  }
  [[noreturn]] void fail(int error) const {
    throw Error("csv_logger: cannot write '" + path_ + "': " + std::strerror(error != 0 ? error : EIO));
  }
  void close() {
    if (file_ != nullptr) std::fclose(file_);
    file_ = nullptr;
  }

  std::string path_, names_;
  bool joints_ = false;
  Nanoseconds period_ = 0, next_ = 0, flush_period_ = 0, next_flush_ = 0;
  std::FILE* file_ = nullptr;
  struct Row {
    const Artifact* artifact;
    const PhysicNode* node;  // null: the artifact's own state (its first root)
    std::string label;       // as written (quoted when it must be)
  };
  std::vector<Row> rows_;
};

}  // namespace ssx::plugins

SSX_PLUGIN(SSX_EXTENSION(ssx::plugins::CsvLogger, "csv_logger"));
