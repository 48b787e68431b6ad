// Buildings from a floor plan: a small YAML format (scenes/README.md) of corridors (centre lines
// with widths), rooms (rectangles or polygons), doors and openings between them, boxes
// (furniture, pillars), lights and named places, from which the MJCF scene is generated: walls,
// door reveals, floor, ceiling, boxes, lights and the robot (an <include> of robot_p2dx.xml).
//
// Geometry (all in the world frame, metres; z up, the floor at z = 0):
// - A space is a simple polygon, kept counter-clockwise. A corridor's polygon is its centre line
//   offset by +-width/2 with mitred joints: at a vertex whose segments have left normals n0, n1
//   the offset point is P +- (width/2) (n0 + n1) / (1 + n0.n1), so the two wall planes of a
//   corner meet exactly on the mitre line, at any angle (turns up to kMaxTurnDeg); the ends are
//   closed by end walls.
// - Every polygon edge is a wall: a visual plane from the floor to the ceiling facing into the
//   space. A door (or an opening: a door as high as the ceiling) joins two spaces whose walls
//   are antiparallel and at most max_door_depth_m apart: each wall is cut at the door's span, a
//   lintel closes the wall above a door lower than the ceiling, and where the walls are apart
//   two jambs and a soffit line the passage (the wall's thickness).
// - The floor and the ceiling are one plane each over the plan's bounding box; boxes are four
//   side planes facing out and a top (none for a box up to the ceiling: a pillar, a core).
// No two drawn planes overlap in a plane: walls meet edge to edge at the mitre points, door cuts
// leave wall pieces and a lintel that share edges, and the floor and ceiling are single pieces.
// That is what keeps the renders free of z-fighting (the hand-written scenes raised overlapping
// floor pieces by 1 mm instead).
//
// Textures: every plane gets its own procedural texture (sim/textures.h), named
// "KIND[-STYLE...]_LABEL" so that the simulator generates it with the surface's style from the
// scenario's texture seed; resolution 256 texels/m on walls and boxes, 200 on the floor, 160 on
// the ceiling (as the hand-written hallways).
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

struct mjModel_;
typedef struct mjModel_ mjModel;

namespace sim {

// The sharpest corner a corridor may turn (degrees between its segments' directions).
constexpr double kMaxTurnDeg = 150.0;
// Texture resolutions of the generated surfaces (texels per metre).
constexpr double kWallPxPerM = 256.0;
constexpr double kFloorPxPerM = 200.0;
constexpr double kCeilingPxPerM = 160.0;
// The most textures a plan may need: MuJoCo 2.2's renderer keeps 100 textures (mjrContext's
// texture[100]); beyond that it draws some surfaces untextured.
constexpr int kMaxPlanTextures = 100;
// The shortest wall piece a door may leave beside it (m): shorter is refused (a sliver).
constexpr double kMinWallPieceM = 0.01;

// How a surface is textured (scenes/README.md, "Textures").
enum class SurfaceStyle {
  kDefault,  // the rich hallway texture of its kind
  kPlain,    // the low-texture variant (plainwall, plainfloor, plainceiling)
  kBusy,     // rich, three times the objects and marks
  kBare,     // rich material without objects (plaster, tiles, panels)
  kPosters,  // walls and boxes only: mostly posters at eye height
};

// One corridor or room.
struct PlanSpace {
  std::string name;
  bool corridor = false;
  std::vector<Eigen::Vector2d> centre;   // corridor: centre line (m), >= 2 points
  double width_m = 0.0;                  // corridor: width (m), > 0
  std::vector<Eigen::Vector2d> polygon;  // the floor outline, counter-clockwise (m)
  SurfaceStyle walls = SurfaceStyle::kDefault;
  std::vector<std::string> wall_names;  // one label per polygon edge ("" = "<space>_<edge>")
};

// A door or opening, resolved onto one edge of each of its two spaces.
struct PlanDoor {
  int space[2] = {-1, -1};    // indices into FloorPlan::spaces
  int edge[2] = {-1, -1};     // edge k of the polygon runs from vertex k to k+1
  double from_m[2] = {0, 0};  // the door's span along each edge, from the edge's start (m)
  double to_m[2] = {0, 0};
  double height_m = 0.0;      // top of the passage (m); the ceiling height for an opening
  double depth_m = 0.0;       // distance between the two walls (m), >= 0
  Eigen::Vector2d centre_xy;  // the door's centre on space[0]'s wall (m)
};

// A box standing on the floor: furniture, a cabinet, a pillar.
struct PlanBox {
  std::string name;
  Eigen::Vector2d centre_xy = Eigen::Vector2d::Zero();  // (m)
  double yaw_rad = 0.0;                                 // the box's x side vs the world's x
  Eigen::Vector2d size_m = Eigen::Vector2d::Ones();     // full sizes along its x and y (m)
  double height_m = 1.0;                                // (m), up to the ceiling
  SurfaceStyle sides = SurfaceStyle::kDefault;
  SurfaceStyle top = SurfaceStyle::kPlain;
  bool wall_like = false;  // sides textured as walls (doors, skirting) rather than furniture
};

struct PlanLight {
  bool directional = true;
  Eigen::Vector3d pos = Eigen::Vector3d(0, 0, 5);  // (m)
  Eigen::Vector3d dir = Eigen::Vector3d(0, 0, -1);
  double diffuse = 0.25;  // grey level of the light's diffuse colour, [0, 1]
  // A point light's cone: MuJoCo's lights that are not directional are spotlights, lighting
  // what lies within cutoff_deg of `dir` (falling off as cos^10 of the angle). 0: not given,
  // MuJoCo's default (45 degrees) and the MJCF carries no cutoff.
  double cutoff_deg = 0.0;
};

struct FloorPlan {
  std::string name;         // the model's name (the file stem unless given)
  std::string source_path;  // the YAML file (empty when built in code)
  std::string robot_path;   // the robot MJCF to include (absolute)
  double ceiling_height_m = 2.5;
  double max_door_depth_m = 0.3;  // the farthest two walls a door may join (m)
  SurfaceStyle floor = SurfaceStyle::kDefault;
  SurfaceStyle ceiling = SurfaceStyle::kDefault;
  std::string floor_name;    // the floor's label (its texture "floor_LABEL"); "" = `name`
  std::string ceiling_name;  // the ceiling's label; "" = `name`
  std::vector<PlanSpace> spaces;
  std::vector<PlanDoor> doors;
  std::vector<PlanBox> boxes;
  std::vector<PlanLight> lights;  // the two default directional lights unless given
  std::vector<std::pair<std::string, Eigen::Vector2d>> places;  // named points, in file order
};

// One generated plane: a MuJoCo plane geom named `name` with the material and texture named
// `texture`. Surfaces of the same size may share one (a door's two jambs, a box's opposite sides,
// never seen together), which keeps a building within kMaxPlanTextures.
struct PlanSurface {
  std::string name;     // the geom: "KIND[-STYLE...]_LABEL"
  std::string texture;  // its material and texture: "KIND[-STYLE...]_..." (sim/textures.h,
                        // ParseTextureName); the name itself unless shared
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();   // (m)
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();  // unit, texture columns grow along it
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();  // unit; the normal x × y faces the viewer
  double half_width_m = 0.0;                          // along x_axis (m)
  double half_height_m = 0.0;                         // along y_axis (m)
  double px_per_m = kWallPxPerM;                      // texture resolution
};

// Reads and checks a plan; errors are "FILE:LINE: key 'K': WHAT" (sim/yaml_input.h): bad YAML,
// unknown keys, more than kMaxPlanTextures textures, a self-intersecting polygon, a zero width, an
// unknown style, overlapping spaces, a door on no wall of its spaces or past a wall's end, a box
// through a wall, ...
bool LoadFloorPlan(const std::string& path, FloorPlan* plan, std::string* error);
// The same on text; `base_dir` resolves the robot file.
bool ParseFloorPlan(const std::string& yaml_text, const std::string& source_name,
                    const std::string& base_dir, FloorPlan* plan, std::string* error);

// The planes of a checked plan: walls (spaces in order, edges in order, pieces along each),
// door jambs and soffits, floor, ceiling, boxes.
std::vector<PlanSurface> PlanSurfaces(const FloorPlan& plan);

// The building's solid side, for the physics only (the drawn planes do not collide: MuJoCo
// planes collide as infinite planes): a box of kSolidThicknessM behind each wall piece and jamb,
// as long and as high as it (thinner where another space's wall faces the other way closer
// behind it: half the gap, at least kMinSolidThicknessM), and each furniture box as a solid box.
// Written in geom group 3 (never drawn, sim/renderer.cc), so the renders are those without them;
// the robot's chassis and wheels collide with them (Simulator's wall_contacts, sim/navigation.h).
constexpr double kSolidThicknessM = 0.05;
constexpr double kMinSolidThicknessM = 0.005;
struct PlanSolid {
  std::string name;  // "solid_" + the surface's name, or "solid_box_" + the box's
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d x_axis = Eigen::Vector3d::UnitX();  // the box's axes (unit)
  Eigen::Vector3d y_axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();  // half extents along x, y, x × y (m)
};
std::vector<PlanSolid> PlanSolids(const FloorPlan& plan);

// The MJCF of a checked plan; `robot_include` is the include's file attribute. `solids`: with
// the collision-only solids of PlanSolids (false: the drawn planes alone, as before them).
std::string FloorPlanToMjcf(const FloorPlan& plan, const std::string& robot_include,
                            bool solids = true);

// True for a path that names a floor plan rather than an MJCF scene (".yaml" or ".yml").
bool IsFloorPlanPath(const std::string& path);

// Loads a scene: an MJCF file, or a floor plan generated in memory (MuJoCo's virtual file
// system, with the plan's robot file). nullptr with *error naming the file on failure.
// `extra_mjcf` (top-level MJCF elements: the people of sim/people.h) is added at the end of the
// scene's <mujoco> element; an MJCF scene is then loaded from MuJoCo's virtual file system under
// a name in its own folder, so that its includes resolve as from the file. Empty: the file as is.
mjModel* LoadSceneModel(const std::string& scene_path, std::string* error,
                        const std::string& extra_mjcf = "");

// A path between two points of a checked plan, for a robot that must stay `clearance_m` from
// every wall piece, jamb and box side below 1.5 m (lintels and soffits are above the robot):
// A* on a grid of `cell_m` cells (8-connected, Euclidean costs and heuristic) over the free
// space (inside a space or a door's passage, the clearance kept), then shortened: from each
// waypoint the farthest later grid point in sight (the straight segment keeps the clearance and
// stays inside) is the next. The result starts at `from` and ends at `to`, each segment checked
// exactly (not on the grid). False with *error when either end is not in free space or no path
// exists (a door narrower than twice the clearance, a room without a door).
bool PlanPath(const FloorPlan& plan, const Eigen::Vector2d& from, const Eigen::Vector2d& to,
              double clearance_m, std::vector<Eigen::Vector2d>* path, std::string* error,
              double cell_m = 0.05);

// Distance from point p to the segment a-b (m).
double PointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b);

// Whether p is inside the polygon or on its boundary (within 1e-9 m).
bool InsidePolygon(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p);

}  // namespace sim
