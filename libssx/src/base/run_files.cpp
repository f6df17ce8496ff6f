#include <ssx/error.hpp>
#include <ssx/run_files.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace ssx {

namespace fs = std::filesystem;

std::string readInputFile(const fs::path& file, std::uintmax_t max_bytes) {
  const SourceLocation where{file.string(), 0};
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0)
    throw ConfigError(where, std::string("cannot read it: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw ConfigError(where, "cannot read it: a directory, not a file");
  if (!S_ISREG(st.st_mode))
    throw ConfigError(where, "cannot read it: not a regular file (a FIFO, a device or a socket has no end or no fixed "
                            "content); give a file");
  const auto too_large = [&](std::uintmax_t size) {
    char text[160];
    std::snprintf(text, sizeof text, "cannot read it: larger than the limit on input files (%.3g MiB; it has at least %.3g MiB)",
                  static_cast<double>(max_bytes) / (1 << 20), static_cast<double>(size) / (1 << 20));
    return ConfigError(where, std::string(text) + ": raise it with --max-input-mb (SceneOptions::max_input_bytes)");
  };
  if (static_cast<std::uintmax_t>(st.st_size) > max_bytes) throw too_large(static_cast<std::uintmax_t>(st.st_size));
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(file.c_str(), "rb"), &std::fclose);
  if (!f) throw ConfigError(where, std::string("cannot read it: ") + std::strerror(errno));
  // read at most one byte beyond the limit: a file that grows while it is read is caught too
  std::string text;
  char buffer[65536];
  for (;;) {
    const std::size_t n = std::fread(buffer, 1, sizeof buffer, f.get());
    text.append(buffer, n);
    if (text.size() > max_bytes) throw too_large(text.size());
    if (n < sizeof buffer) break;
  }
  if (std::ferror(f.get()) != 0) throw ConfigError(where, std::string("cannot read it: ") + std::strerror(errno));
  return text;
}

std::FILE* openOutputFile(const fs::path& file, bool append) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : 0), 0644);
  if (fd < 0) throw Error("cannot create '" + file.string() + "': " + std::strerror(errno));
  struct stat st {};
  const bool regular = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (regular && ::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int error = errno;
    ::close(fd);
    if (error == EWOULDBLOCK)
      throw Error("'" + file.string() + "' is being written by another run now (it holds the file's lock): wait for "
                  "it to end, or give this run another file");
    throw Error("cannot lock '" + file.string() + "': " + std::strerror(error));
  }
  if (regular && !append && ::ftruncate(fd, 0) != 0) {
    const int error = errno;
    ::close(fd);
    throw Error("cannot empty '" + file.string() + "' to write it: " + std::strerror(error));
  }
  std::FILE* f = ::fdopen(fd, append ? "ab" : "wb");
  if (f == nullptr) {
    const int error = errno;
    ::close(fd);
    throw Error("cannot write '" + file.string() + "': " + std::strerror(error));
  }
  return f;
}

bool RunFiles::Identity::operator==(const Identity& o) const {
  if (exists && o.exists) return device == o.device && inode == o.inode;
  return path == o.path;
}

RunFiles::Identity RunFiles::identify(const fs::path& file) {
  Identity id;
  std::error_code ec;
  id.path = fs::weakly_canonical(fs::absolute(file, ec), ec).lexically_normal().string();
  struct stat st {};
  if (::stat(file.c_str(), &st) == 0) {  // (follows links: a link names the file it points to)
    id.exists = true;
    id.device = static_cast<std::uintmax_t>(st.st_dev);
    id.inode = static_cast<std::uintmax_t>(st.st_ino);
  }
  return id;
}

void RunFiles::addInput(const fs::path& file) {
  const Identity id = identify(file);
  for (const Identity& known : input_ids_)
    if (known == id) return;
  inputs_.push_back(file);
  input_ids_.push_back(id);
}

std::string RunFiles::claimOutput(const fs::path& path, const std::string& what, bool replaced,
                                  bool makes_directory) {
  const std::string named = what + " '" + path.string() + "'";
  if (path.empty()) return what + ": an empty path";
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  const fs::file_status target = fs::status(path, ec);
  const bool special = fs::is_fifo(target) || fs::is_character_file(target);
  const bool streamed = !replaced && allow_special_ && special;
  if (fs::is_symlink(link) && !streamed)
    return named + " is a symbolic link: a run replaces its outputs, and would replace the link; give the file "
                   "it points to";
  if (fs::exists(link) && !streamed) {
    if (fs::is_directory(target)) return named + " is a directory: give a file name";
    if (!fs::is_regular_file(link))
      return named + " is not a regular file (a FIFO, a device or a socket): " +
             (replaced || !special ? std::string("a run replaces this output")
                                   : std::string("to write a stream into it, allow special outputs "
                                                 "(ssx run --allow-special-outputs)"));
  } else if (!fs::exists(link) && !makes_directory) {
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) return named + ": the directory '" + dir.string() + "' does not exist";
  }
  const Identity id = identify(path);
  for (std::size_t i = 0; i < input_ids_.size(); ++i)
    if (input_ids_[i] == id)
      return named + " is '" + inputs_[i].string() + "', which this run reads: a run never writes its own inputs";
  for (std::size_t i = 0; i < output_ids_.size(); ++i)
    if (output_ids_[i] == id)
      return named + " is '" + outputs_[i].string() + "', which this run writes already: give each output a file "
                     "of its own";
  outputs_.push_back(path);
  output_ids_.push_back(id);
  return {};
}

std::string RunFiles::claimOutputDirectory(const fs::path& dir, const std::string& what) {
  const std::string named = what + " '" + dir.string() + "'";
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(dir, ec);
  if (fs::exists(link) && !fs::is_directory(fs::status(dir, ec))) return named + " is not a directory";
  // ("frames/" is "frames")
  const Identity id = identify(dir.has_filename() || !dir.has_parent_path() ? dir : dir.parent_path());
  const std::string prefix = id.path + "/";
  for (std::size_t i = 0; i < input_ids_.size(); ++i)
    if (input_ids_[i].path.rfind(prefix, 0) == 0)
      return named + " holds '" + inputs_[i].string() + "', which this run reads: write frames into a directory "
                     "of their own";
  // two writers of numbered frames in one directory would write over each other's files
  for (std::size_t i = 0; i < directory_ids_.size(); ++i)
    if (directory_ids_[i] == id)
      return named + " is '" + directories_[i].string() + "', which this run writes frames into already: give each "
                     "camera a directory of its own";
  directories_.push_back(dir);
  directory_ids_.push_back(id);
  return {};
}

}  // namespace ssx
