// diefill itself under mpirun (docs/ARCHITECTURE.md, "Domain decomposition"): the pipeline on the
// ring over 2 and 3 ranks fills as one process does and repeats its bits on the same rank count,
// a checkpoint that 2 ranks wrote resumes on 3, clump grains split too, and an overlap past the limit stops every rank
// with exit status 3 and a checkpoint.
#include <fmt/core.h>

#include <chrono>
#include <map>
#include <nlohmann/json.hpp>

#include "clump_report.hpp"
#include "support.hpp"

namespace {

namespace fs = std::filesystem;

// Two cores run up to three ranks of one thread each.
test::Run mpirun(int ranks, const std::string& arguments) {
  return test::run_command(fmt::format("{} -np {} --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 {} {} 2>&1",
                                       DIEFILL_MPIRUN, ranks, DIEFILL_EXECUTABLE, arguments));
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

fs::path suite_out() { return test::suite_folder("mpi"); }

// No FEM hand-off: nothing here reads it, and rank 0 would mesh while the other spins. Grains of
// 2.26 mm (α = 22.6): what is tested is that a split run is another realisation of the one-process
// fill, which holds at any grain size (with 1.6 mm grains this test took 131 s on two cores, now 78).
const std::string ring = fmt::format("{}/dies/ring.stl --set powder.coarse_graining=22.6 --set fem.elements=none", DIEFILL_SOURCE_DIR);

// The ring at α = 22.6, 0.1 m/s, run by one process on seeds 1 to 15 (measured 2026-12-06:
// `diefill run dies/ring.stl --set powder.coarse_graining=22.6 --set fem.elements=none --seed N`):
// 711 grains inserted on seed 1; fill ratio mean 0.4856, standard deviation 0.0059 over the seeds
// (0.4772 to 0.4937). A run split over ranks is another realisation of the same fill (rounding
// differences grow in the chaotic flow as a new seed's do), so its fill ratio lies within four
// deviations of the mean.
constexpr double single_process_fill_mean = 0.4856, single_process_fill_sd = 0.0059;
constexpr int grains_inserted_on_seed_1 = 711;

// Runs (once per folder) the ring split over `ranks` ranks into suite_out()/folder.
const nlohmann::json& ring_report(int ranks, const std::string& folder) {
  static std::map<std::string, nlohmann::json> done;
  if (auto it = done.find(folder); it != done.end()) return it->second;
  const test::Run run = mpirun(ranks, "run " + ring + " --out " + (suite_out() / folder).string());
  EXPECT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(count(run.output, "ring: report "), 1u) << "rank 0 alone reports:\n" << run.output;
  return done[folder] = nlohmann::json::parse(test::read_text(suite_out() / folder / "ring" / "report.json"));
}

void expect_fills_as_one_process(const nlohmann::json& report, const std::string& what) {
  EXPECT_EQ(report["particles"]["inserted"], grains_inserted_on_seed_1) << what;
  EXPECT_EQ(report["particles"]["lost"], 0) << what;
  EXPECT_NEAR(report["fill"]["fill_ratio"].get<double>(), single_process_fill_mean, 4 * single_process_fill_sd) << what;
}

}  // namespace

TEST(MpiRun, TheRingOverTwoAndThreeRanksFillsAsOneProcessAndRepeatsItsBits) {
  nlohmann::json first = ring_report(2, "two");
  nlohmann::json again = ring_report(2, "two_again");
  const nlohmann::json& three = ring_report(3, "three");
  EXPECT_EQ(first["timing"]["ranks"], 2);
  EXPECT_EQ(first["timing"]["threads_per_rank"], 1);
  EXPECT_EQ(three["timing"]["ranks"], 3);
  expect_fills_as_one_process(first, "on 2 ranks");
  expect_fills_as_one_process(three, "on 3 ranks");
  // Each settled its own shoe, split over two ranks, and filled the die from it: the same bits.
  first.erase("timing"), again.erase("timing");
  EXPECT_EQ(first.dump(), again.dump());
  EXPECT_EQ(test::read_text(suite_out() / "two" / "ring" / "particles.csv"),
            test::read_text(suite_out() / "two_again" / "ring" / "particles.csv"));
}

// Stopped by Ctrl-C at mpirun (which sends its ranks SIGTERM) while two ranks fill the die, the
// run leaves a checkpoint; three ranks resume it and end as the uninterrupted two-rank run from
// the same settled shoe does, within the spread of realisations.
TEST(MpiRun, ACheckpointOfTwoRanksResumesOnThree) {
  const nlohmann::json& uninterrupted = ring_report(2, "two");
  const fs::path dir = suite_out() / "interrupted";
  fs::create_directories(dir);
  fs::copy(suite_out() / "two" / ".cache", dir / ".cache", fs::copy_options::recursive);  // the same settled shoe
  const std::string args = "run " + ring + " --out " + dir.string();
  // The shoe is cached, and the fill lasts a few seconds: stopped a second into it. (mpirun gives
  // its ranks a second after SIGTERM before it kills them; they stop after the step that sees it.)
  const fs::path log_file = dir / "stopped.log";
  test::run_command(fmt::format("bash -c '{} -np 2 --oversubscribe --allow-run-as-root -x OMP_NUM_THREADS=1 {} {} > {} 2>&1 & "
                                "pid=$!; for i in $(seq 300); do grep -q filling: {} && break; sleep 0.1; done; sleep 1; "
                                "kill -INT $pid; wait $pid'",
                                DIEFILL_MPIRUN, DIEFILL_EXECUTABLE, args, log_file.string(), log_file.string()));
  const std::string log = test::read_text(log_file);
  ASSERT_TRUE(fs::exists(dir / "ring" / "checkpoint.bin")) << log;
  // The hint repeats the run's own arguments, its folder included.
  EXPECT_NE(log.find(fmt::format("interrupted; resume with `diefill run {}/dies/ring.stl --out {} --set powder.coarse_graining=22.6 "
                                 "--set fem.elements=none --resume`",
                                 DIEFILL_SOURCE_DIR, dir.string())),
            std::string::npos)
      << log;
  const test::Run resumed = mpirun(3, args + " --resume");
  ASSERT_EQ(resumed.status, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resumed at"), std::string::npos) << resumed.output;
  const nlohmann::json report = nlohmann::json::parse(test::read_text(dir / "ring" / "report.json"));
  EXPECT_EQ(report["timing"]["ranks"], 3);
  // The resumed trajectory depends on when the interrupt landed, so it is one more draw of the
  // fill from the uninterrupted run's settled shoe: every grain counted, and the fill within four
  // seed deviations of that run's (not of the seeds' mean: a settled shoe shifts the fill its draws
  // scatter about). A grain or two may spill over the table's edge beside the shoe in such a draw:
  // counted as particles.spilled, harmless to the fill; particles.lost counts faults only (issue
  // 44). A grain through the die would have stopped the run (check_losses).
  const nlohmann::json& p = report["particles"];
  EXPECT_EQ(p["inserted"], grains_inserted_on_seed_1);
  EXPECT_EQ(p["lost"].get<std::int64_t>(), 0);
  EXPECT_EQ(p["inserted"].get<std::int64_t>(), p["in_cavity"].get<std::int64_t>() + p["in_shoe"].get<std::int64_t>() +
                                                   p["elsewhere"].get<std::int64_t>() + p["spilled"].get<std::int64_t>());
  EXPECT_NEAR(report["fill"]["fill_ratio"].get<double>(), uninterrupted["fill"]["fill_ratio"].get<double>(),
              4 * single_process_fill_sd);
  EXPECT_FALSE(fs::exists(dir / "ring" / "checkpoint.bin")) << "a finished run removes its checkpoint";
}

// Capsule grains as rigid clumps, settled in the shoe and poured into the ring over two ranks:
// every clump lives on one rank, so the census adds up (every grain counted once, none lost), the
// binned volume is the grains' true volume, and rank 0 alone reports and warns.
TEST(MpiRun, ClumpGrainsFillTheRingOverTwoRanks) {
  REQUIRE_SHARED_MESHES();
  const std::string capsule = (test::shared_meshes() / "grains" / "capsule_trimesh.obj").string();
  // 1.6 mm grains (α = 16): the census asks for more than a hundred clumps in the cavity.
  const std::string ring_at_16 = fmt::format("{}/dies/ring.stl --set powder.coarse_graining=16 --set fem.elements=none", DIEFILL_SOURCE_DIR);
  const test::Run run = mpirun(2, "run " + ring_at_16 + " --set powder.shape.mesh=\"" + capsule +
                                      "\" --set powder.shape.tolerance=0.05 --out " + (suite_out() / "clumps").string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_EQ(count(run.output, "ring: report "), 1u) << run.output;
  EXPECT_LE(count(run.output, "warning: ring: the shoe holds"), 1u) << "rank 0 alone warns:\n" << run.output;
  const nlohmann::json r = nlohmann::json::parse(test::read_text(suite_out() / "clumps" / "ring" / "report.json"));
  EXPECT_EQ(r["timing"]["ranks"], 2);
  test::expect_clump_fill_census(r);
}

// Two grains of 200 overlap by 1.4 radii at the start, on one rank: every rank stops at the first
// step's check, with exit status 3, one message and a checkpoint, in seconds.
TEST(MpiSimulate, AnOverlapPastTheLimitOnOneRankStopsEveryRank) {
  test::TempDir dir;
  std::string csv = "id,x,y,z,vx,vy,vz,wx,wy,wz,radius\n";
  for (int n = 0; n < 199; ++n)
    csv += fmt::format("{},{},{},{},0,0,0,0,0,0,5e-4\n", n, (n % 10) * 1.1e-3, (n / 10 % 5) * 1.1e-3, (n / 50) * 1.1e-3 + 1e-3);
  csv += "199,3e-4,0,1e-3,0,0,0,0,0,0,5e-4\n";  // 0.3 mm from grain 0: overlapping by 0.7 mm
  test::write_text(dir / "particles.csv", csv);
  test::write_text(dir / "scene.toml", "[simulation]\nduration = 0.01\n\n[[materials]]\nname = \"glass\"\nyoungs_modulus = 5e6\n"
                                       "\n[particles]\nfile = \"particles.csv\"\n"
                                       "\n[[walls]]\ntype = \"plane\"\nnormal = [0.0, 0.0, 1.0]\n");
  const auto start = std::chrono::steady_clock::now();
  const test::Run run = mpirun(2, "simulate " + (dir / "scene.toml").string() + " --out " + (dir / "out").string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(run.status, 3) << run.output;
  EXPECT_EQ(count(run.output, "stopped: a contact overlap reached"), 1u) << run.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "checkpoint.bin"));
  EXPECT_LT(seconds, 10.0);
}
