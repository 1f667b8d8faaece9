// The case file (TOML) as a plain C++ value. docs/case-format.md documents every key;
// io/case_*.cpp are the only places that know the TOML spelling (io/case_reader.cpp
// lists them).
#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace fdem::io {

struct MeshConfig {
  std::string file;         // .msh path, resolved relative to the case file ("" when geo is used)
  std::string geo;          // .geo path, resolved relative to the case file ("" when file is used)
  double size = 0.0;        // element size passed to gmsh (-setnumber size); 0 = the .geo's default
  double scale = 1.0;       // coordinates × scale → metres
  double thickness = 1.0;   // out-of-plane thickness [m]
  int refine = 0;           // times every triangle is split into four after reading (io::refine_mesh)
  std::string algorithm;    // gmsh's 2D algorithm for a .geo ("" = the .geo's own / gmsh's default)
  std::string order = "hilbert";  // triangle numbering: "hilbert" (along a Hilbert curve, the default) or "file" (the mesh file's)
  double perturb = 0.0;     // mesh.perturb.amplitude: random moves of fracturable interior nodes (io::perturb_mesh)
  long perturb_seed = 1;
  double perturb_min_quality = 0.5;
};

struct TimeConfig {
  bool dt_auto = false;     // dt = "auto": safety × stable estimate
  double dt = 0.0;          // [s] when not auto
  double safety = 0.5;      // used by dt = "auto"
  double end = -1.0;        // [s]; < 0 when steps is given instead
  long steps = -1;          // number of steps; < 0 when end is given instead
};

struct OutputConfig {
  std::string dir = "out";  // resolved relative to the current working directory
  std::string name;         // base name of the output files; default: case file stem; one file name (docs/case-format.md, [output])
  int frames = -1;          // number of frames (first and last included); < 0 when every is given
  double every = -1.0;      // [s] time between frames; < 0 when frames is given
  double history_every = -1.0;  // [s]; < 0: steps/1000 steps
  std::vector<std::string> regions;  // extra regions whose mean displacement the history records
  double checkpoint_every = 0;  // [s] simulated time between checkpoints; 0: only at the end
  double energy_limit = 0.05;  // largest |energy_error| (history; fraction) a run accepts; > 0
  bool float_frames = false;  // precision = "float": frame values stored as float (coordinates stay double)
  bool compress = false;      // compress = true: netCDF-4 Exodus file, deflated frame values (not crash-safe)
  // [output] events = { distance, window }: grouping of breaks into events; 0: the
  // default from the mesh and the wave speed (engine/outputs/fracture_events.hpp).
  double events_distance = 0;  // [m]
  double events_window = 0;    // [s]
};

enum class Elasticity { NeoHookean, Hyperelastic };
enum class Plane { Strain, Stress };

// Anisotropic constants in the material frame (Voigt on xx, yy, xy with engineering
// shear strain), and the angle [deg] from the global x axis to the material's 1 axis,
// counter-clockwise.
struct Stiffness {
  double c11 = 0, c22 = 0, c12 = 0, c66 = 0, c16 = 0, c26 = 0;
  double angle = 0.0;
};

// Cohesive properties of a [material.fracture] or an [[interface]]: the CE4 law of
// Eqs. 4–14 (engine/model/cohesive_model.hpp's FractureProperties).
struct FractureConfig {
  double tensile_strength = 0, cohesion = 0, friction_angle = 0, gf1 = 0, gf2 = 0;
  double penalty_opening = 0, penalty_sliding = 0, penalty_overlap = 0;
  double softening_a = 0.63, softening_b = 1.8, softening_c = 6.0;
  // model = "extrinsic": a CE4 only once its edge's traction reaches the peak (ECZM);
  // "intrinsic" (the default): a CE4 on every interior edge from the start.
  bool extrinsic = false;
};

// [material.heterogeneity]: per-element properties drawn from a Weibull distribution of
// shape m (the homogeneity index) and scale the material's own value (RFPA's rule).
struct HeterogeneityConfig {
  double homogeneity = 0.0;  // m > 0
  std::uint64_t seed = 0;
  bool young = false;             // E per triangle
  bool tensile_strength = false;  // T_s per CE4 of the material
  bool cohesion = false;          // c per CE4 of the material
};

struct MaterialConfig {
  std::string name;
  std::vector<std::string> regions;  // Gmsh physical surfaces
  double density = 0.0;              // [kg/m³]
  double young = 0.0;                // [Pa]
  double poisson = 0.0;
  Elasticity elasticity = Elasticity::NeoHookean;
  Plane plane = Plane::Strain;
  std::optional<Stiffness> stiffness;  // only with elasticity = hyperelastic
  bool viscosity_critical = false;     // viscosity = "critical": 2 h √(ρE)
  double viscosity = 0.0;              // [Pa·s] when not critical
  std::optional<FractureConfig> fracture;  // [material.fracture]: its regions can fracture
  std::optional<HeterogeneityConfig> heterogeneity;  // [material.heterogeneity]
};

// One [[interface]]: the cohesive properties of the CE4s between two different
// fracturable materials (names of [[material]] entries that have [material.fracture]).
struct InterfaceConfig {
  std::array<std::string, 2> materials;
  FractureConfig fracture;
};

// One [[joint]]: pre-existing joints, the mesh edges along the listed physical curves,
// whose CE4s take these properties instead of their material's or interface's. A
// broken joint has no strength: its CE4s start closed (frictional contact through the
// CE4's compression branch and friction element), with `fracture` holding only the
// friction angle and the penalties that matter to a closed CE4.
//
// The joints are the union of three sources, at least one given: `curves` (physical
// curves of the mesh), `file` (polylines, io/joint_geometry.hpp) and `set` (a
// statistical joint set drawn from a seed). The last two need mesh.geo: the front end
// embeds them into the .geo it meshes, so that element edges follow them.
struct JointSetConfig {
  double angle = 0;          // [deg] mean trace direction, counter-clockwise from x
  double kappa = 0;          // von Mises (2D Fisher) concentration of the directions; 0 uniform
  double spacing = 0;        // [m] mean spacing of the joint lines along their mean normal (exponential)
  double trace_length = 0;  // [m] length of each trace
  double persistence = 1;    // (0, 1]: share of a joint line that is joint (the rest rock bridges)
  std::uint64_t seed = 0;
};
struct JointConfig {
  std::string name;                 // "joint<i>" when not given
  std::vector<std::string> curves;  // Gmsh physical curves
  std::string file;                 // polylines [m], absolute path ("" none)
  std::optional<JointSetConfig> set;
  bool broken = false;
  FractureConfig fracture;
};

// [grains]: a physical surface cut into Voronoi grains (io/grain_geometry.hpp). Seeds are
// drawn uniformly over the region from `seed`; each grain's mineral (a [[material]]) is
// drawn so that the area fractions are met approximately. The cells' edges are embedded
// into the .geo (element edges follow them); a CE4 between two grains takes `boundary`,
// one inside a grain its mineral's [material.fracture].
struct GrainsConfig {
  std::string region;                 // physical surface
  double size = 0;                    // [m] mean grain diameter (0: `count` given)
  long count = 0;                     // number of grains (0: from `size`)
  std::uint64_t seed = 0;
  std::vector<std::string> minerals;  // [[material]] names, each with [material.fracture]
  std::vector<double> fractions;      // area fractions, summing to 1
  FractureConfig boundary;            // [grains.boundary]
  // Filled by the front end (io::draw_grains, engine/run/prepare_case.cpp) from the mesh
  // as read: the seed points [m] and each grain's mineral (index into `minerals`).
  std::vector<std::array<double, 2>> points;
  std::vector<int> mineral;
  // The cells as embedded (io::grain_boundaries: polygons over the merged vertices).
  std::vector<std::vector<std::array<double, 2>>> cells;
};

struct GravityConfig {
  std::array<double, 2> g{0.0, 0.0};  // [m/s²]
};

// [in_situ]: the initial stress field (tension positive). σ₀(x, y) = stress + the depth
// part: with `datum`, σ_yy = -ρ g (datum - y), σ_xx = k_x σ_yy, k_x = k_H cos²α + k_h sin²α
// (α = azimuth, the angle from the model's x axis to σ_H), σ_xy = 0.
struct InSituConfig {
  std::array<double, 3> stress{0.0, 0.0, 0.0};  // uniform part (σxx, σyy, σxy) [Pa]
  std::optional<double> datum;                  // y of the ground surface [m]: the depth part
  std::optional<double> density;                // ρ of the overburden [kg/m³]; nullopt: the materials'
  double k_H = 1.0, k_h = 1.0;                  // σ_H / σ_v, σ_h / σ_v
  double azimuth = 0.0;                         // α [degrees]
};

// One [[excavation]]: the triangles of a physical surface removed from the model. Their
// internal forces (and stored strain energy) are scaled by a factor that falls linearly
// from 1 at `start` to 0 at `start + duration` (duration 0: at once, at the first step at
// or after `start`).
struct ExcavationConfig {
  std::string region;     // Gmsh physical surface
  double start = 0.0;     // [s]
  double duration = 0.0;  // [s]
};

struct DampingConfig {
  bool local_enabled = false;  // [damping] local given
  double local = 0.0;          // Cundall α
  bool mass_scaling = false;
};

// pressure = { times = [...], values = [...] }: piecewise linear in time, held at the
// first and last values outside the times.
struct PressureTable {
  std::vector<double> times;   // [s], increasing
  std::vector<double> values;  // [Pa]
};

// blast = { peak, rise, ratio }: the blast-hole pressure of the paper's Eq. 21.
struct BlastConfig {
  double peak = 0;   // P₀ [Pa], reached at t = rise
  double rise = 0;   // t₀ [s]
  double ratio = 0;  // β/α > 1
};

struct BoundaryConfig {
  std::string region;                          // Gmsh physical curve or surface
  bool fix_x = false, fix_y = false;           // fix = ["x"], ["y"] or ["x", "y"]
  std::optional<std::array<double, 2>> velocity;  // prescribed velocity [m/s]
  double rise = 0.0;                           // ramp time [s] for velocity, traction, pressure
  std::optional<std::array<double, 2>> traction;  // [Pa] on a physical curve
  std::optional<double> pressure;              // [Pa], positive pushes into the body
  std::optional<PressureTable> pressure_table; // pressure given as a table instead of a number
  std::optional<BlastConfig> blast;            // Eq. 21 pressure on a blast hole
  bool absorbing = false;                      // viscous non-reflecting boundary (Eq. 20)
  bool in_situ = false;                        // in_situ = true: the [in_situ] field's traction σ₀·n (dead load)
  bool gas = false;  // not a key: the hole of [fluid.gas], whose pressure the gas's state gives (engine/model)
};

// [fluid]: a viscous, slightly compressible fluid in the cracks (engine/stages/fluid_flow.*).
// The source injects either a volume rate per unit thickness or holds a pressure; each is
// a number or a piecewise linear table in time.
// [fluid.gas]: the explosion products in a blast hole, a polytropic gas p = p0 (ρ/ρ0)^γ
// that fills the hole and flows into the cracks connected to it.
struct GasConfig {
  double gamma = 0;     // γ > 1
  double density = 0;   // ρ0 [kg/m³]: the products' density at the start (filling the hole)
  double pressure = 0;  // p0 [Pa]: their pressure at ρ0
  std::string hole;     // the physical curve of the hole's wall (a closed curve)
};

struct FluidConfig {
  double viscosity = 0;          // μ [Pa s]
  double bulk_modulus = 0;       // K_f [Pa]
  double residual_aperture = 0;  // w_r [m], added to the CE4's opening
  double max_aperture = 0;       // w_max [m]: the stable fluid step is planned for it
  double safety = 0.5;           // fluid sub-step = safety × stable fluid step
  double leak_off = 0;           // Carter's C_L [m/√s]; 0: no leak-off
  bool damaged_segments = true;  // segments = "damaged": softened intact CE4s carry fluid; "broken": broken ones only
  std::string crack;             // physical curve whose CE4s start broken ("": none)
  std::string source;            // physical point or curve the fluid enters at
  std::optional<PressureTable> rate;      // Q(t) [m²/s] (volume per second per metre of thickness)
  std::optional<PressureTable> pressure;  // p(t) [Pa] held at the source
  std::optional<GasConfig> gas;           // a gas from a blast hole instead (no bulk_modulus, source, rate, pressure)
  bool cap_aperture = false;  // aperture_limit = "cap": conductances use min(w_m, max_aperture), no stop
};

struct InitialConfig {
  std::string region;                 // Gmsh physical surface or curve
  std::array<double, 2> velocity{0.0, 0.0};  // [m/s]
};

// An–Tannant contact damping. A table without `transition` means T = ∞.
struct ContactDampingConfig {
  double transition = std::numeric_limits<double>::infinity();  // T [Pa]
  double exponent = 1.0;                                         // b
};

// One [[contact.pair]]: overrides of the [contact] defaults for one unordered pair of
// materials (names of [[material]] entries, possibly the same twice). nullopt = the
// [contact] value.
struct ContactPairConfig {
  std::array<std::string, 2> materials;
  std::optional<double> normal_penalty, tangential_penalty, friction;
  std::optional<ContactDampingConfig> damping;
};

enum class ContactRebuild { Step, Skin };

struct ContactConfig {
  double normal_penalty = 0.0;      // P_n [Pa]
  // P_tan [Pa/m]. nullopt: not given; the model takes 6 P_n / h for each pair, h the mean
  // triangle edge of the mesh (engine/model/model.hpp, default_tangential_penalty).
  std::optional<double> tangential_penalty;
  double friction = 0.0;            // Coulomb μ
  std::optional<ContactDampingConfig> damping;  // nullopt: elastic contact
  std::string activation = "all";   // "all" or "fractured"
  ContactRebuild rebuild = ContactRebuild::Skin;  // the default: the fast path
  // [m] margin added to the boxes (> 0 with Skin). nullopt: not given; with Skin the model
  // takes kDefaultSkinFraction × the mean edge length of the mesh (engine/model/model.cpp), with
  // Step the boxes are not enlarged.
  std::optional<double> skin;
  // With Skin: `skin` = "auto" or left out, the skin is picked again at each detection
  // from the speeds (ContactSkin::choose), starting from the mesh's default; a number
  // fixes it.
  bool skin_auto = false;
  std::vector<ContactPairConfig> pairs;
  // With activation = "fractured": regions (Gmsh physical groups) whose triangles are
  // contact candidates from the start.
  std::vector<std::string> regions;
};

// One [[probe]]: a history point. Its velocity (nearest node) and stress (the element
// containing the point) go to the history file as <name>_vx, <name>_sxx, ...
struct ProbeConfig {
  std::string name;                 // unique; letters, digits, '_' (netCDF variable prefix)
  std::array<double, 2> point{0.0, 0.0};  // [m] (after mesh.scale)
};

struct CaseConfig {
  std::string path;  // the case file as given
  std::string dir;   // its directory (relative paths in the case resolve against it)
  std::string title;
  MeshConfig mesh;
  TimeConfig time;
  OutputConfig output;
  std::vector<MaterialConfig> materials;
  GravityConfig gravity;
  DampingConfig damping;
  std::vector<BoundaryConfig> boundaries;
  std::vector<InitialConfig> initials;
  std::optional<ContactConfig> contact;   // present when the case has a [contact] table
  std::vector<InterfaceConfig> interfaces;
  std::vector<JointConfig> joints;        // [[joint]] entries
  std::optional<GrainsConfig> grains;     // present when the case has a [grains] table
  std::vector<ProbeConfig> probes;        // [[probe]] entries
  std::optional<InSituConfig> in_situ;    // present when the case has an [in_situ] table
  std::vector<ExcavationConfig> excavations;  // [[excavation]] entries
  std::optional<FluidConfig> fluid;       // present when the case has a [fluid] table
  // Every key of the case after --set, by dotted path ("material.0.young") → its TOML
  // value; checkpoints keep it so that a restart can name any key that changed.
  std::map<std::string, std::string> settings;
  // The same keys → where their value came from, as messages write it ("case.toml:12",
  // "case.toml (from --set time.end=1)"): for checks made after reading (run_steps).
  std::map<std::string, std::string> origin;
  std::string text;  // the case file's text as read
};

// Reads and validates a case file. `overrides` are "key.path=value" strings from
// --set, applied before validation (value parsed as TOML; arrays of tables by index,
// e.g. "material.0.young=2e9"). Throws fdem::InputError naming the file, line and key
// for: unreadable file, TOML syntax error, unknown key or table (with the nearest valid
// name as a suggestion), missing required key (naming its table), wrong type, value out
// of range, and a bad --set.
CaseConfig read_case(const std::string& path, const std::vector<std::string>& overrides = {});

// Where the key's value came from ("case.toml:12", or the --set), or the case path when
// the key is absent: the prefix of a message about it.
std::string origin_of(const CaseConfig& c, const std::string& key);

// The most steps a run may take: 2^53, the largest count a double holds exactly with
// every count below it (the time n × dt, the frame schedule and the restart's step of a
// time are computed in doubles).
constexpr long kMaxSteps = 1L << 53;
// The most frames a run may write (output.frames, or the frames output.every gives).
constexpr long kMaxFrames = 1000000;

// The number of steps of the run at time step `dt` [s]: time.steps, or time.end / dt
// rounded up (at least 1). Checks first that the count and the output schedule fit, and
// throws InputError naming the key, its file and line otherwise: at most kMaxSteps
// steps, a finite end time steps × dt, output.every and output.history_every at most
// kMaxSteps steps apart, and at most steps + 1 frames (a frame per step and one at
// t = 0), and at most kMaxFrames. read_case calls it with a numeric dt; with
// dt = "auto" it calls it with dt = 0, which checks only what does not depend on dt
// (time.steps, output.frames against kMaxFrames, and against steps + 1 when time.steps
// is given) and returns time.steps, or -1 when the count needs dt. With dt = "auto" the
// run must call it again with the dt it uses, before anything is allocated from the
// counts.
long run_steps(const CaseConfig& c, double dt);

}  // namespace fdem::io
