// Our recursive coordinate bisection (dem/rcb_partition.hpp) beside Zoltan's RCB on the same
// weighted grains, under mpirun (issue 18 asks for Zoltan or a measurement that ours is as good):
// the balance (the heaviest rank's weight over the mean), the ghosts each rank would hold (other
// ranks' grains within ghost reach of its box, as mpi_exchange.cpp sends them) and the time of a
// cut (median of five, the slowest rank's). Every rank reads the whole particles file and keeps
// every ranks-th grain, as a run starts. A grain weighs 1 + its pairs within the neighbour range
// r_i + r_j + skin (skin half the largest radius, as compile_model sets it), each pair counted on
// its lower index, as the half neighbour list counts it.
//   mpirun -np N build/bench/partition PARTICLES.csv   -> one JSON line on rank 0
#include <mpi.h>
#include <zoltan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <tuple>
#include <vector>

#include "core/error.hpp"
#include "dem/io.hpp"
#include "dem/rcb_partition.hpp"

namespace {

using dem::Vec3;

struct Grains {
  std::vector<Vec3> x;
  std::vector<double> radius;
  std::vector<std::int64_t> weight;
  double reach = 0;  // of a ghost: 2 r_max + skin
};

Grains weighed(const dem::State& s) {
  Grains g{{s.x.begin(), s.x.end()}, {s.radius.begin(), s.radius.end()}, std::vector<std::int64_t>(s.size(), 1), 0};
  const double r_max = *std::max_element(g.radius.begin(), g.radius.end()), skin = 0.5 * r_max;
  g.reach = 2 * r_max + skin;
  const double cell = g.reach;
  std::map<std::tuple<long, long, long>, std::vector<std::size_t>> cells;
  const auto key = [&](const Vec3& p) { return std::tuple{long(std::floor(p.x() / cell)), long(std::floor(p.y() / cell)), long(std::floor(p.z() / cell))}; };
  for (std::size_t i = 0; i < g.x.size(); ++i) cells[key(g.x[i])].push_back(i);
  for (std::size_t i = 0; i < g.x.size(); ++i) {
    const auto [a, b, c] = key(g.x[i]);
    for (long da = -1; da <= 1; ++da)
      for (long db = -1; db <= 1; ++db)
        for (long dc = -1; dc <= 1; ++dc)
          if (const auto at = cells.find({a + da, b + db, c + dc}); at != cells.end())
            for (std::size_t j : at->second)
              if (j > i && (g.x[i] - g.x[j]).norm() < g.radius[i] + g.radius[j] + skin) ++g.weight[i];
  }
  return g;
}

struct Quality {
  double imbalance = 0, largest_share_with_ghosts = 0, cut_seconds = 0;
  std::int64_t largest_ghosts = 0, ghosts = 0;
};

// From each local grain's rank and the ranks' boxes.
Quality quality(const Grains& g, const std::vector<std::size_t>& mine, const std::vector<int>& owner, const std::vector<dem::Box>& boxes) {
  const int ranks = int(boxes.size());
  std::vector<std::int64_t> weight(std::size_t(ranks), 0), held(std::size_t(ranks), 0), ghosts(std::size_t(ranks), 0);
  for (std::size_t k = 0; k < mine.size(); ++k) {
    weight[std::size_t(owner[k])] += g.weight[mine[k]];
    ++held[std::size_t(owner[k])];
    for (int r = 0; r < ranks; ++r)
      if (r != owner[k] && boxes[std::size_t(r)].distance(g.x[mine[k]]) < g.reach) ++ghosts[std::size_t(r)], ++held[std::size_t(r)];
  }
  for (auto* v : {&weight, &held, &ghosts}) MPI_Allreduce(MPI_IN_PLACE, v->data(), ranks, MPI_INT64_T, MPI_SUM, MPI_COMM_WORLD);
  Quality q;
  std::int64_t total = 0;
  for (std::int64_t w : weight) total += w;
  q.imbalance = double(*std::max_element(weight.begin(), weight.end())) * ranks / double(total);
  q.largest_share_with_ghosts = double(*std::max_element(held.begin(), held.end())) / double(g.x.size());
  q.largest_ghosts = *std::max_element(ghosts.begin(), ghosts.end());
  for (std::int64_t n : ghosts) q.ghosts += n;
  return q;
}

// The slowest rank's time of `cut`, median of five.
template <typename F>
double median_seconds(F&& cut) {
  std::vector<double> times;
  for (int k = 0; k < 5; ++k) {
    MPI_Barrier(MPI_COMM_WORLD);
    double t = MPI_Wtime();
    cut();
    t = MPI_Wtime() - t;
    MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    times.push_back(t);
  }
  std::sort(times.begin(), times.end());
  return times[2];
}

Quality ours(const Grains& g, const std::vector<std::size_t>& mine) {
  std::vector<dem::WeightedPoint> points;
  for (std::size_t i : mine) points.push_back({g.x[i], g.weight[i]});
  dem::RcbPartition rcb;
  const double seconds = median_seconds([&] { rcb.cut(points); });
  std::vector<int> owner;
  for (std::size_t i : mine) owner.push_back(rcb.owner(g.x[i]));
  Quality q = quality(g, mine, owner, rcb.boxes());
  q.cut_seconds = seconds;
  return q;
}

struct ZoltanInput {
  const Grains* grains;
  const std::vector<std::size_t>* mine;
};

Quality zoltan(const Grains& g, const std::vector<std::size_t>& mine, int ranks, int rank) {
  ZoltanInput input{&g, &mine};
  Zoltan_Struct* zz = Zoltan_Create(MPI_COMM_WORLD);
  // Its tightest balance (the default tolerates 10 %), and the boxes kept for the ghost count.
  for (const auto& [name, value] : {std::pair{"DEBUG_LEVEL", "0"}, {"LB_METHOD", "RCB"}, {"OBJ_WEIGHT_DIM", "1"},
                                    {"KEEP_CUTS", "1"}, {"RETURN_LISTS", "EXPORT"}, {"IMBALANCE_TOL", "1.0"}})
    Zoltan_Set_Param(zz, name, value);
  Zoltan_Set_Num_Obj_Fn(zz, [](void* d, int* err) { *err = ZOLTAN_OK; return int(static_cast<ZoltanInput*>(d)->mine->size()); }, &input);
  Zoltan_Set_Obj_List_Fn(
      zz,
      [](void* d, int, int, ZOLTAN_ID_PTR gids, ZOLTAN_ID_PTR lids, int, float* weights, int* err) {
        const auto* in = static_cast<ZoltanInput*>(d);
        for (std::size_t k = 0; k < in->mine->size(); ++k) {
          gids[k] = ZOLTAN_ID_TYPE((*in->mine)[k]);
          lids[k] = ZOLTAN_ID_TYPE(k);
          weights[k] = float(in->grains->weight[(*in->mine)[k]]);
        }
        *err = ZOLTAN_OK;
      },
      &input);
  Zoltan_Set_Num_Geom_Fn(zz, [](void*, int* err) { *err = ZOLTAN_OK; return 3; }, nullptr);
  Zoltan_Set_Geom_Multi_Fn(
      zz,
      [](void* d, int, int, int n, ZOLTAN_ID_PTR, ZOLTAN_ID_PTR lids, int, double* xyz, int* err) {
        const auto* in = static_cast<ZoltanInput*>(d);
        for (int k = 0; k < n; ++k)
          for (int a = 0; a < 3; ++a) xyz[3 * k + a] = in->grains->x[(*in->mine)[lids[k]]][a];
        *err = ZOLTAN_OK;
      },
      &input);
  std::vector<int> owner(mine.size(), rank);
  const double seconds = median_seconds([&] {
    int changes = 0, gid_entries = 0, lid_entries = 0, imports = 0, exports = 0;
    ZOLTAN_ID_PTR import_gids = nullptr, import_lids = nullptr, export_gids = nullptr, export_lids = nullptr;
    int *import_procs = nullptr, *import_parts = nullptr, *export_procs = nullptr, *export_parts = nullptr;
    if (Zoltan_LB_Partition(zz, &changes, &gid_entries, &lid_entries, &imports, &import_gids, &import_lids, &import_procs,
                            &import_parts, &exports, &export_gids, &export_lids, &export_procs, &export_parts) != ZOLTAN_OK)
      throw diefill::InputError("zoltan", "", "Zoltan_LB_Partition failed", "");
    std::fill(owner.begin(), owner.end(), rank);
    for (int k = 0; k < exports; ++k) owner[export_lids[k]] = export_parts[k];
    Zoltan_LB_Free_Part(&import_gids, &import_lids, &import_procs, &import_parts);
    Zoltan_LB_Free_Part(&export_gids, &export_lids, &export_procs, &export_parts);
  });
  std::vector<dem::Box> boxes(static_cast<std::size_t>(ranks));
  for (int r = 0; r < ranks; ++r) {
    int dims = 0;
    dem::Box& b = boxes[std::size_t(r)];
    Zoltan_RCB_Box(zz, r, &dims, &b.lo.x(), &b.lo.y(), &b.lo.z(), &b.hi.x(), &b.hi.y(), &b.hi.z());
  }
  Zoltan_Destroy(&zz);
  Quality q = quality(g, mine, owner, boxes);
  q.cut_seconds = seconds;
  return q;
}

nlohmann::json as_json(const Quality& q) {
  return {{"imbalance", q.imbalance}, {"largest_share_with_ghosts", q.largest_share_with_ghosts},
          {"largest_ghosts", q.largest_ghosts}, {"ghosts", q.ghosts}, {"cut_seconds", q.cut_seconds}};
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  float version = 0;
  Zoltan_Initialize(argc, argv, &version);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (argc != 2) {
    if (rank == 0) std::fprintf(stderr, "usage: mpirun -np N %s PARTICLES.csv\n", argv[0]);
    MPI_Finalize();
    return 2;
  }
  const Grains g = weighed(dem::read_particles_csv(argv[1], 0, 2500));
  std::vector<std::size_t> mine;
  for (std::size_t i = std::size_t(rank); i < g.x.size(); i += std::size_t(ranks)) mine.push_back(i);
  const Quality diefill = ours(g, mine), reference = zoltan(g, mine, ranks, rank);
  if (rank == 0) {
    const nlohmann::json result = {{"file", argv[1]},      {"grains", g.x.size()},     {"ranks", ranks},
                                   {"diefill_rcb", as_json(diefill)}, {"zoltan_rcb", as_json(reference)}, {"zoltan_version", version}};
    std::printf("%s\n", result.dump().c_str());
  }
  MPI_Finalize();
  return 0;
}
