// A virtual X display for the window tests. Xvfb picks a free display number itself (-displayfd:
// it takes the first number whose lock it can create and writes it back), so tests run side by
// side under `ctest -j`, or beside another user's X server, never collide. `up` says whether it
// started; `number` is its display.
#pragma once
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace furrow::cli_test {

struct Xvfb {
  pid_t pid = -1;
  int number = -1;
  bool up = false;
  Xvfb() {
    int fds[2];
    if (::pipe(fds) != 0) return;
    pid = fork();
    if (pid == 0) {
      ::close(fds[0]);
      if (!freopen("/dev/null", "w", stderr)) _exit(127);
      const std::string fd = std::to_string(fds[1]);
      execlp("Xvfb", "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "1600x900x24", "-nolisten", "tcp", (char*)nullptr);
      _exit(127);
    }
    ::close(fds[1]);
    // the display number, newline-terminated, once the server listens (up to 10 s)
    std::string text;
    pollfd p{fds[0], POLLIN, 0};
    while (pid > 0 && text.find('\n') == std::string::npos && ::poll(&p, 1, 10000) > 0) {
      char buf[16];
      const ssize_t n = ::read(fds[0], buf, sizeof buf);
      if (n <= 0) break;
      text.append(buf, size_t(n));
    }
    ::close(fds[0]);
    if (text.find('\n') != std::string::npos) {
      number = std::atoi(text.c_str());
      up = waitpid(pid, nullptr, WNOHANG) == 0;
    }
  }
  ~Xvfb() {
    if (pid > 0) {
      kill(pid, SIGTERM);
      waitpid(pid, nullptr, 0);
    }
  }
};

}  // namespace furrow::cli_test
