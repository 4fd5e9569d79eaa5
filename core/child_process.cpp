#include "core/child_process.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include "core/timer.hpp"

namespace diefill {

namespace {

bool write_all(int fd, const char* p, std::size_t bytes) {
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n <= 0) return false;
    p += n, bytes -= std::size_t(n);
  }
  return true;
}

ChildResult run_here(const std::function<std::string()>& work) {
  try {
    return {ChildOutcome::done, work(), 0};
  } catch (const std::exception&) {
    return {ChildOutcome::failed, {}, 0};
  }
}

}  // namespace

ChildResult run_in_child(const std::function<std::string()>& work, const ChildWait& wait) {
  int fds[2];
  if (::pipe(fds) != 0) return run_here(work);
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]), ::close(fds[1]);
    return run_here(work);
  }
  if (child == 0) {
    ::close(fds[0]);
    for (int signal : {SIGINT, SIGTERM, SIGUSR1}) std::signal(signal, SIG_DFL);
    int code = 1;
    try {
      const std::string bytes = work();
      code = write_all(fds[1], bytes.data(), bytes.size()) ? 0 : 1;
    } catch (...) {
      code = 2;
    }
    ::_exit(code);
  }
  ::close(fds[1]);
  ChildResult result;
  Stopwatch clock;
  double next_report = wait.report_every_s;
  char buffer[1 << 16];
  for (;;) {
    pollfd readable{fds[0], POLLIN, 0};
    const int ready = ::poll(&readable, 1, 1000);
    if (ready > 0) {
      const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
      if (n <= 0) break;  // the child closed its end: it is done, or gone
      result.bytes.append(buffer, std::size_t(n));
      continue;
    }
    if (wait.stop && wait.stop()) {
      ::kill(child, SIGKILL);
      result.outcome = ChildOutcome::stopped;
      break;
    }
    if (wait.waiting && clock.seconds() >= next_report) {
      wait.waiting(clock.seconds());
      next_report += wait.report_every_s;
    }
  }
  ::close(fds[0]);
  ::waitpid(child, &result.status, 0);
  if (result.outcome == ChildOutcome::stopped) {
    result.bytes.clear();
    return result;
  }
  const bool exited_well = WIFEXITED(result.status) && WEXITSTATUS(result.status) == 0;
  // Ctrl-C at a terminal reaches the child too, which dies of it before the parent polls.
  result.outcome = exited_well ? ChildOutcome::done : wait.stop && wait.stop() ? ChildOutcome::stopped : ChildOutcome::failed;
  if (!exited_well) result.bytes.clear();
  return result;
}

}  // namespace diefill
