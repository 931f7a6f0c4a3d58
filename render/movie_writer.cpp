#include "render/movie_writer.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

extern char** environ;

namespace fs = std::filesystem;

namespace furrow::render {

namespace {

std::string fps_text(double fps) {
  std::ostringstream os;
  os.precision(10);
  os << fps;
  return os.str();
}

// Writes all bytes to a pipe without letting a dead reader kill us with SIGPIPE: the signal is
// blocked for this thread during the write and a SIGPIPE it raised is consumed afterwards.
bool write_all(int fd, const uint8_t* data, size_t n, int* err) {
  sigset_t pipe_set, old_mask, pending_before;
  sigemptyset(&pipe_set);
  sigaddset(&pipe_set, SIGPIPE);
  sigpending(&pending_before);
  const bool was_pending = sigismember(&pending_before, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_set, &old_mask);
  bool ok = true;
  while (n > 0) {
    ssize_t w = ::write(fd, data, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      *err = errno;
      ok = false;
      break;
    }
    data += w;
    n -= size_t(w);
  }
  if (!ok && *err == EPIPE && !was_pending) {
    const timespec zero{0, 0};
    sigtimedwait(&pipe_set, nullptr, &zero);
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  return ok;
}

}  // namespace

MovieWriter::MovieWriter(const std::string& path, int width, int height, double fps, bool overwrite)
    : path_(path), width_(width), height_(height), overwrite_(overwrite) {
  if (width <= 0 || height <= 0 || width % 2 != 0 || height % 2 != 0)
    throw std::invalid_argument(path + ": movie frame size " + std::to_string(width) + "x" +
                                std::to_string(height) +
                                " is not allowed; H.264 with yuv420p needs positive, even width and height");
  if (!(fps > 0)) throw std::invalid_argument(path + ": frames per second must be > 0, got " + fps_text(fps));
  if (!overwrite && fs::exists(path)) throw std::runtime_error(path + ": already exists; not overwriting it");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent))
    throw std::runtime_error(path + ": directory " + parent.string() + " does not exist");

  temp_path_ = temp_path_for(path);
  log_path_ = temp_path_ + ".log";

  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));

  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  const std::string rate = fps_text(fps);
  std::vector<std::string> args = {"ffmpeg", "-hide_banner", "-nostdin", "-loglevel", "error", "-y",
                                   "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", size, "-r", rate, "-i", "-",
                                   "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", "18",
                                   "-movflags", "+faststart", temp_path_};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, log_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const int rc = posix_spawnp(&pid_, "ffmpeg", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[0]);
  if (rc != 0) {
    ::close(fds[1]);
    pid_ = -1;
    std::error_code ec;
    fs::remove(log_path_, ec);
    throw std::runtime_error(path + ": cannot start ffmpeg (" + std::strerror(rc) +
                             "); install the 'ffmpeg' package and make sure it is on PATH");
  }
  pipe_fd_ = fds[1];
}

MovieWriter::~MovieWriter() {
  if (!finished_) abort_encoder();
}

void MovieWriter::abort_encoder() {
  if (pipe_fd_ >= 0) {
    ::close(pipe_fd_);
    pipe_fd_ = -1;
  }
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }
  std::error_code ec;
  fs::remove(temp_path_, ec);
  fs::remove(log_path_, ec);
}

std::string MovieWriter::ffmpeg_message() const {
  std::ifstream in(log_path_);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text.empty() ? "no message" : text;
}

void MovieWriter::add_frame(const RgbImage& frame) {
  if (finished_ || pipe_fd_ < 0) throw std::logic_error(path_ + ": add_frame after finish");
  if (frame.width != width_ || frame.height != height_)
    throw std::invalid_argument(path_ + ": frame is " + std::to_string(frame.width) + "x" +
                                std::to_string(frame.height) + ", movie is " + std::to_string(width_) + "x" +
                                std::to_string(height_));
  int err = 0;
  if (!write_all(pipe_fd_, frame.rgb.data(), frame.rgb.size(), &err)) {
    const std::string msg = ffmpeg_message();
    abort_encoder();
    finished_ = true;
    throw std::runtime_error(path_ + ": ffmpeg stopped accepting frames (" + std::strerror(err) + "): " + msg);
  }
  ++frames_;
}

void MovieWriter::finish() {
  if (finished_) return;
  if (frames_ == 0) {
    abort_encoder();
    finished_ = true;
    throw std::runtime_error(path_ + ": no frames were given; not writing an empty movie");
  }
  ::close(pipe_fd_);
  pipe_fd_ = -1;
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  finished_ = true;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string msg = ffmpeg_message();
    abort_encoder();
    throw std::runtime_error(path_ + ": ffmpeg failed: " + msg);
  }
  std::error_code ec;
  fs::remove(log_path_, ec);
  publish_file(temp_path_, path_, overwrite_);
}

}  // namespace furrow::render
