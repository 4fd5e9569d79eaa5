// `diefill bench [CASE...]`: the performance cases of bench/cases.hpp, their JSON on standard
// output or into --json.
#include <fmt/core.h>

#include "bench/cases.hpp"
#include "cli/commands.hpp"
#include "cli/mpi_session.hpp"
#include "core/atomic_file.hpp"
#include "core/error.hpp"

namespace cli {

int run_bench(const BenchCommand& c) {
  const std::shared_ptr<dem::Exchange> ranks = mpi_exchange();  // the cases split under mpirun
  const std::string text = bench::run_cases(c.request, ranks).dump(2) + "\n";
  if (ranks && ranks->rank() != 0) return diefill::exit_ok;  // rank 0 reports
  if (c.json_out.empty()) fmt::print("{}", text);
  else diefill::write_file_atomic(c.json_out, text);
  return diefill::exit_ok;
}

}  // namespace cli
