// Start-up: a whole `flexure analyze` of a triangle, and of the double Watt mechanism, as a
// process (fork, exec, load, parse, analyse, print, exit), 50 times each; CPU time of the child
// (user + system, from wait4) and wall time, minimum and median. The same with `flexure-draw`
// (every command, the renderer, video and HTTP libraries linked) shows what the split saves.
// Usage: bench_startup BUILD_DIR SCENES_DIR
#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace {

struct Times {
  double cpu, wall;
};

Times once(const std::string& binary, const std::vector<std::string>& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    std::vector<char*> argv{const_cast<char*>(binary.c_str())};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  struct rusage ru {};
  ::wait4(pid, &status, 0, &ru);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::fprintf(stderr, "bench_startup: %s failed\n", binary.c_str());
    std::exit(1);
  }
  const double cpu = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  return {cpu, wall};
}

void bench(const std::string& label, const std::string& binary, const std::vector<std::string>& args) {
  std::vector<double> cpu, wall;
  for (int i = 0; i < 50; ++i) {
    const Times t = once(binary, args);
    cpu.push_back(t.cpu), wall.push_back(t.wall);
  }
  std::sort(cpu.begin(), cpu.end());
  std::sort(wall.begin(), wall.end());
  std::printf("%-44s CPU min %6.1f ms  median %6.1f ms   wall min %6.1f ms  median %6.1f ms\n", label.c_str(),
              1e3 * cpu.front(), 1e3 * cpu[cpu.size() / 2], 1e3 * wall.front(), 1e3 * wall[wall.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_startup BUILD_DIR SCENES_DIR\n");
    return 2;
  }
  const std::string build = argv[1], scenes = argv[2];
  char tri[] = "/tmp/bench_startup_XXXXXX.toml";
  const int fd = ::mkstemps(tri, 5);
  const std::string text =
      "[system]\ntype = \"framework\"\nvertices = [[0, 0], [1, 0], [0, 1]]\nedges = [[1, 2], [2, 3], [3, 1]]\n";
  if (fd < 0 || ::write(fd, text.data(), text.size()) != static_cast<ssize_t>(text.size())) return 1;
  ::close(fd);
  for (const char* bin : {"flexure", "flexure-draw"}) {
    const std::string b = build + "/" + bin;
    bench(std::string(bin) + " analyze triangle", b, {"analyze", tri});
    bench(std::string(bin) + " analyze double_watt", b, {"analyze", scenes + "/double_watt.toml"});
    bench(std::string(bin) + " --version", b, {"--version"});
  }
  ::unlink(tri);
  return 0;
}
