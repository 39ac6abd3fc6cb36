#include "cli_runner.h"

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace spherekit::test {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string shell_quote(const std::string& s) { return "'" + s + "'"; }

int run_shell(const std::string& cmd, const std::string& out_file, const std::string& err_file) {
  const std::string full = cmd + " </dev/null >" + shell_quote(out_file) + " 2>" + shell_quote(err_file);
  const int status = std::system(full.c_str());
  return (status != -1 && WIFEXITED(status)) ? WEXITSTATUS(status) : -1;
}

CliRun run_cli(const std::string& exe, const std::string& args, const std::string& capture_dir) {
  const std::string out = capture_dir + "/stdout.txt", err = capture_dir + "/stderr.txt";
  CliRun r;
  r.exit_code = run_shell(shell_quote(exe) + " " + args, out, err);
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace spherekit::test
