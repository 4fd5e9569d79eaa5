#pragma once
// The bench experiments the studies share.
//  - Slot container: a box (x: length, y: width) whose floor has a slot across its whole width,
//    closed by a gate while the poured powder settles, then opened: grains leave through the
//    slot (counted as they drop below the floor) until the run ends or the flow stops. Gives the
//    discharge rate (Beverloo slot law) and, once drained, the outflow angle of what remains.
//  - Heap: grains rained onto a round pedestal from a narrow stream above its centre; those
//    rolling over the edge fall away. Gives the heap angle of repose.
#include <string>
#include <vector>

#include "studies/study_kit.hpp"

namespace studies {

double grain_volume(double diameter);  // [m³] of a sphere
// Height below which a fraction `q` of the active grains' centres lie [m].
double centre_height_quantile(const dem::State& state, double q);

struct SlotContainer {
  double length = 0, width = 0, fill_height = 0;  // inner [m]; the slot runs along y, across the width
  double slot_width = 0;                          // [m], centred at x = 0
  double slot_length = 0;                         // [m] along y, centred; 0: the whole width (a square slot: an orifice)
  double settle_time = 0.15;                      // [s] with the gate shut
  double flow_time = 0.3;                         // [s] after opening, at most
  double sample_every = 2.5e-3;                   // [s]
  bool stop_when_drained = false;                 // end early once no grain has left for 0.1 s
  bool stop_after_steady_flow = false;            // end once steady_rate has all it reads
};

// The container whose drained slopes give the outflow angle (and, while it drains, a flow rate):
// a slot 6 grains wide, 10 (reduced) or 14 grains of floor beside it, run until no grain leaves.
SlotContainer outflow_container(double diameter, bool reduced);

// The powder poured into the container and settled on the shut gate.
struct SlotBed {
  double bulk_density = 0;  // of the settled bed [kg/m³]
  double bed_height = 0;    // [m]
  double initial_mass = 0;  // [kg]
  dem::State state;         // settled; once drained, at the end
};
struct SlotRun : SlotBed {
  std::vector<double> time, discharged;  // since the opening [s]; mass below the floor or gone [kg]
};

// Settles a bed, then opens the gate over the slot.
SlotRun run_slot_container(const Powder& powder, const SlotContainer& container, const std::string& label);
// The two halves, for beds drained through several slots: the gate covers the whole floor, so
// a bed settled in `container` drains through any slot of a container of its size.
SlotBed settle_slot_bed(const Powder& powder, const SlotContainer& container, const std::string& label);
SlotRun drain_slot_bed(const Powder& powder, const SlotContainer& container, SlotBed bed, const std::string& label);
// A settled bed drained through the walls of `open_walls` (its gate gone), a grain counted out
// once below `gone_below` [m]; `timing` gives the sampling, the longest flow and when to stop.
SlotRun drain_bed(const Powder& powder, const dem::ModelSpec& open_walls, const SlotContainer& timing, SlotBed bed, double gone_below,
                  const std::string& label);
// The Beverloo slot law's geometry (L - k d)(b - k d)^{3/2} [m^{5/2}]: the rate over C_s rho_b sqrt(g).
double beverloo_slot(double length, double width, double k, double d);
// The steady discharge rate [kg/s]: a line through the discharged mass after the opening's
// transient (50 ms) and before the bed has lost 40 % (its head then drops).
inline constexpr double steady_flow_transient = 0.05, steady_flow_until_lost = 0.4;  // [s], of the bed's mass
LineFit steady_rate(const SlotRun& run);

struct Heap {
  double pedestal_radius = 0;  // [m]
  double pour_rate = 0;        // grains per second
  std::size_t grains = 0;      // poured in all
  double drop_height = 0;      // of the stream's outlet above the heap's apex [m]
  double stream_radius = 0;    // [m]
  double settle_time = 0.15;   // after the last batch [s]
};

struct HeapRun {
  dem::State state;
  std::size_t on_pedestal = 0;
};

HeapRun run_heap(const Powder& powder, const Heap& heap, const std::string& label);
// The heap of the fixed-base funnel test on a pedestal `pedestal_grains` grains of `diameter` in
// radius, poured in about a second.
Heap funnel_heap(double diameter, double pedestal_grains);

// A free surface: the highest grain top per column, fitted with a straight line between `from`
// and `to` along the column coordinate.
struct SurfaceFit {
  double angle_deg = 0, angle_error_deg = 0;
  std::vector<double> position, height;  // the columns used [m]
};
// Columns one grain wide along |x| on one side of the slot (side = -1 or +1) in the drained
// container, `clear` [m] kept clear of the slot's edge and of the end wall.
SurfaceFit fit_outflow_surface(const dem::State& state, const SlotContainer& container, double diameter, int side,
                               double clear);
// The outflow angle: the mean of both sides' fits, with its standard error.
struct OutflowAngle {
  double angle_deg = 0, error_deg = 0, left_deg = 0, right_deg = 0;
};
OutflowAngle outflow_angle(const dem::State& state, const SlotContainer& container, double diameter, double clear);
// Beds of one powder drained alike (other seeds): the mean of their angles, its error the larger
// of the beds' own and their scatter's.
OutflowAngle pooled(const std::vector<OutflowAngle>& beds);
// Columns along the radius of the heap.
SurfaceFit fit_heap_surface(const dem::State& state, const Heap& heap, double diameter);

}  // namespace studies
