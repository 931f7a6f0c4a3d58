// A virtual X display for the window tests: Xvfb on a display number of this process's own;
// `up` says whether it started.
#pragma once
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

namespace furrow::cli_test {

struct Xvfb {
  pid_t pid = -1;
  int number = 0;
  bool up = false;
  Xvfb() {
    number = 200 + int(::getpid() % 500);
    pid = fork();
    if (pid == 0) {
      const std::string d = ":" + std::to_string(number);
      freopen("/dev/null", "w", stderr);
      execlp("Xvfb", "Xvfb", d.c_str(), "-screen", "0", "1600x900x24", "-nolisten", "tcp", (char*)nullptr);
      _exit(127);
    }
    const std::string socket = "/tmp/.X11-unix/X" + std::to_string(number);
    for (int k = 0; k < 100 && pid > 0 && !up; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      up = std::filesystem::exists(socket) && waitpid(pid, nullptr, WNOHANG) == 0;
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
