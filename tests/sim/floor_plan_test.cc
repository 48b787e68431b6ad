// Floor plans (sim/floor_plan.h): the generator on known plans (wall positions, mitre joints at
// any angle, door cuts and reveals, exact), bad plans refused at file:line, scenarios that say
// floor_plan:, the generated scene loading with its robot, determinism.
#include "sim/floor_plan.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "sim/scenario.h"
#include "sim/scene_walls.h"
#include "sim/textures.h"
#include "sim_test_util.h"

namespace {

using vobench_test::TempDir;
using vobench_test::WriteText;

constexpr double kExact = 1e-12;  // generated coordinates are closed-form: exact to rounding

std::map<std::string, sim::PlanSurface> ByName(const std::vector<sim::PlanSurface>& v) {
  std::map<std::string, sim::PlanSurface> m;
  for (const auto& s : v) m[s.name] = s;
  return m;
}

sim::FloorPlan Parse(const std::string& yaml) {
  sim::FloorPlan plan;
  std::string error;
  EXPECT_TRUE(sim::ParseFloorPlan(yaml, "plan.yaml", ".", &plan, &error)) << error;
  return plan;
}

// The two ends of a vertical surface in the plan (the viewer sees a on the right).
void Ends(const sim::PlanSurface& s, Eigen::Vector2d* a, Eigen::Vector2d* b) {
  const Eigen::Vector2d x = s.x_axis.head<2>();
  *a = s.centre.head<2>() + s.half_width_m * x;
  *b = s.centre.head<2>() - s.half_width_m * x;
}

TEST(FloorPlanTest, TheLHallwayPlanGivesTheHandWrittenWalls) {
  // scenes/hallway_l.xml's six walls, positions and axes as written by hand.
  const sim::FloorPlan plan = Parse(R"(
name: l
corridors:
  - name: hall
    centre: [[-1.5, 0], [8, 0], [8, 12]]
    width_m: 2
    wall_names: [south, east, end, west, north, back]
)");
  const auto s = ByName(sim::PlanSurfaces(plan));
  struct Want {
    const char* name;
    double cx, cy, half, ax, ay;
  } want[] = {{"wall_south", 3.75, -1, 5.25, -1, 0}, {"wall_east", 9, 5.5, 6.5, 0, -1},
              {"wall_end", 8, 12, 1, 1, 0},          {"wall_west", 7, 6.5, 5.5, 0, 1},
              {"wall_north", 2.75, 1, 4.25, 1, 0},   {"wall_back", -1.5, 0, 1, 0, 1}};
  for (const Want& w : want) {
    ASSERT_TRUE(s.count(w.name)) << w.name;
    const sim::PlanSurface& p = s.at(w.name);
    EXPECT_NEAR(p.centre.x(), w.cx, kExact) << w.name;
    EXPECT_NEAR(p.centre.y(), w.cy, kExact) << w.name;
    EXPECT_NEAR(p.centre.z(), 1.25, kExact) << w.name;
    EXPECT_NEAR(p.half_width_m, w.half, kExact) << w.name;
    EXPECT_NEAR(p.half_height_m, 1.25, kExact) << w.name;
    EXPECT_NEAR(p.x_axis.x(), w.ax, kExact) << w.name;
    EXPECT_NEAR(p.x_axis.y(), w.ay, kExact) << w.name;
    EXPECT_EQ(p.y_axis, Eigen::Vector3d::UnitZ()) << w.name;
  }
  // One floor and one ceiling over the bounding box, facing in.
  ASSERT_TRUE(s.count("floor_l") && s.count("ceiling_l"));
  EXPECT_NEAR(s.at("floor_l").centre.x(), 3.75, kExact);
  EXPECT_NEAR(s.at("floor_l").half_height_m, 6.5, kExact);
  EXPECT_GT(s.at("floor_l").x_axis.cross(s.at("floor_l").y_axis).z(), 0.99);
  EXPECT_LT(s.at("ceiling_l").x_axis.cross(s.at("ceiling_l").y_axis).z(), -0.99);
  EXPECT_EQ(s.size(), 8u);
}

TEST(FloorPlanTest, MitredJointsAtAnyAngleMeetOnTheBisector) {
  // A corridor turning by 30, 60, 90, 120 and 150 deg: at each corner the two walls of a side
  // end at the same point, on the bisector, at half-width / cos(turn / 2) from the centre.
  for (double turn_deg : {30.0, 60.0, 90.0, 120.0, 150.0}) {
    const double t = turn_deg * M_PI / 180.0;
    const Eigen::Vector2d c1(4, 0), c2 = c1 + 5.0 * Eigen::Vector2d(std::cos(t), std::sin(t));
    char yaml[512];
    std::snprintf(yaml, sizeof(yaml),
                  "corridors:\n  - name: c\n    centre: [[0, 0], [4, 0], [%.17g, %.17g]]\n"
                  "    width_m: 1.6\n",
                  c2.x(), c2.y());
    const sim::FloorPlan plan = Parse(yaml);
    ASSERT_EQ(plan.spaces.size(), 1u);
    const auto walls = sim::PlanSurfaces(plan);
    // Polygon: R0 R1 R2 L2 L1 L0; walls c_0 (R0-R1), c_1 (R1-R2), c_3 (L2-L1), c_4 (L1-L0).
    const auto s = ByName(walls);
    Eigen::Vector2d a0, b0, a1, b1;
    Ends(s.at("wall_c_0"), &a0, &b0);
    Ends(s.at("wall_c_1"), &a1, &b1);
    EXPECT_NEAR((b0 - a1).norm(), 0.0, 1e-12) << turn_deg;  // the right side meets
    const double mitre = 0.8 / std::cos(t / 2);
    const Eigen::Vector2d bisector_right(std::sin(t / 2), -std::cos(t / 2));
    EXPECT_NEAR((b0 - (c1 + mitre * bisector_right)).norm(), 0.0, 1e-12) << turn_deg;
    Ends(s.at("wall_c_3"), &a0, &b0);
    Ends(s.at("wall_c_4"), &a1, &b1);
    EXPECT_NEAR((b0 - a1).norm(), 0.0, 1e-12) << turn_deg;  // the left side meets
    EXPECT_NEAR((b0 - (c1 - mitre * bisector_right)).norm(), 0.0, 1e-12) << turn_deg;
    // The joint angle: the walls' directions differ by exactly the turn.
    const double angle =
        std::acos(std::clamp(s.at("wall_c_0").x_axis.dot(s.at("wall_c_1").x_axis), -1.0, 1.0));
    EXPECT_NEAR(angle, t, 1e-12) << turn_deg;
  }
}

TEST(FloorPlanTest, DoorsCutBothWallsAndLineThePassage) {
  // A corridor y -1..1 and a room whose south wall is 0.1 m north of it; a 1 m door at x = 3,
  // 2.1 m high under a 2.5 m ceiling.
  const sim::FloorPlan plan = Parse(R"(
name: d
corridors:
  - {name: c, centre: [[0, 0], [10, 0]], width_m: 2, walls: busy}
rooms:
  - {name: r, rect: [1, 1.1, 6, 5], walls: posters}
doors:
  - {between: [c, r], at: [3, 1.05], width_m: 1, height_m: 2.1}
)");
  ASSERT_EQ(plan.doors.size(), 1u);
  EXPECT_NEAR(plan.doors[0].depth_m, 0.1, kExact);
  const auto s = ByName(sim::PlanSurfaces(plan));
  // The corridor's north wall (edge 2: (10, 1) -> (0, 1)) in three pieces: x 3.5..10, the
  // lintel x 2.5..3.5 from 2.1 m, x 0..2.5.
  Eigen::Vector2d a, b;
  ASSERT_TRUE(s.count("wall-busy_c_2_0") && s.count("wall-busy_c_2_1") &&
              s.count("wall-busy_c_2_2"));
  Ends(s.at("wall-busy_c_2_0"), &a, &b);
  EXPECT_NEAR((a - Eigen::Vector2d(10, 1)).norm(), 0, kExact);
  EXPECT_NEAR((b - Eigen::Vector2d(3.5, 1)).norm(), 0, kExact);
  const sim::PlanSurface& lintel = s.at("wall-busy_c_2_1");
  EXPECT_NEAR(lintel.centre.x(), 3.0, kExact);
  EXPECT_NEAR(lintel.centre.z() - lintel.half_height_m, 2.1, kExact);
  EXPECT_NEAR(lintel.centre.z() + lintel.half_height_m, 2.5, kExact);
  Ends(s.at("wall-busy_c_2_2"), &a, &b);
  EXPECT_NEAR((a - Eigen::Vector2d(2.5, 1)).norm(), 0, kExact);
  EXPECT_NEAR((b - Eigen::Vector2d(0, 1)).norm(), 0, kExact);
  // The room's south wall (edge 0: (1, 1.1) -> (6, 1.1)) cut at the same span.
  Ends(s.at("wall-posters_r_0_0"), &a, &b);
  EXPECT_NEAR((b - Eigen::Vector2d(2.5, 1.1)).norm(), 0, kExact);
  Ends(s.at("wall-posters_r_0_2"), &a, &b);
  EXPECT_NEAR((a - Eigen::Vector2d(3.5, 1.1)).norm(), 0, kExact);
  // Jambs 0.1 m deep facing into the passage, and the soffit facing down at 2.1 m.
  const sim::PlanSurface& j0 = s.at("wall-furniture-busy_door0_jamb0");
  const sim::PlanSurface& j1 = s.at("wall-furniture-busy_door0_jamb1");
  EXPECT_NEAR(j0.half_width_m, 0.05, kExact);
  EXPECT_NEAR(j0.centre.x(), 3.5, kExact);
  EXPECT_NEAR(j1.centre.x(), 2.5, kExact);
  EXPECT_NEAR(j0.x_axis.cross(j0.y_axis).x(), -1.0, kExact);  // at x 3.5, facing -x
  EXPECT_NEAR(j1.x_axis.cross(j1.y_axis).x(), 1.0, kExact);
  const sim::PlanSurface& soffit = s.at("plainceiling_door0");
  EXPECT_NEAR(soffit.centre.z(), 2.1, kExact);
  EXPECT_NEAR(soffit.centre.y(), 1.05, kExact);
  EXPECT_LT(soffit.x_axis.cross(soffit.y_axis).z(), -0.99);
  // Every generated name parses as a texture with its style.
  EXPECT_EQ(j0.texture, j1.texture);  // the same size: one texture
  for (const auto& [name, surface] : s) {
    sim::TextureKind kind;
    sim::TextureOptions options;
    EXPECT_TRUE(sim::ParseTextureName(surface.texture, &kind, &options)) << surface.texture;
  }
  sim::TextureKind kind;
  sim::TextureOptions options;
  ASSERT_TRUE(sim::ParseTextureName("wall-busy-furniture_x", &kind, &options));
  EXPECT_EQ(kind, sim::TextureKind::kWall);
  EXPECT_EQ(options.detail_density, 3.0);
  EXPECT_FALSE(options.doors);
  EXPECT_FALSE(sim::ParseTextureName("wall-shiny_x", &kind, &options));
}

TEST(FloorPlanTest, BoxesAreTexturedOnEverySide) {
  const sim::FloorPlan plan = Parse(R"(
name: b
rooms:
  - {name: r, rect: [0, 0, 6, 4]}
boxes:
  - {name: desk, at: [3, 2], yaw_deg: 90, size_m: [1.2, 0.6], height_m: 0.75, sides: busy}
  - {name: pillar, at: [1, 1], size_m: [0.4, 0.4], height_m: 2.5, wall: true}
)");
  const auto s = ByName(sim::PlanSurfaces(plan));
  for (int k = 0; k < 4; ++k) {
    const sim::PlanSurface& side = s.at("wall-furniture-busy_box_desk_" + std::to_string(k));
    // Facing out: the normal points away from the box's centre.
    const Eigen::Vector3d n = side.x_axis.cross(side.y_axis);
    EXPECT_GT(n.head<2>().dot(side.centre.head<2>() - Eigen::Vector2d(3, 2)), 0.29);
    EXPECT_NEAR(side.centre.z(), 0.375, kExact);
  }
  EXPECT_NEAR(s.at("plainfloor_box_desk_top").centre.z(), 0.75, kExact);
  EXPECT_TRUE(s.count("wall_box_pillar_0"));  // a pillar: wall texture, doors possible
  EXPECT_EQ(s.at("wall_box_pillar_2").texture, "wall_box_pillar_0");  // opposite sides share
}

TEST(FloorPlanTest, BadPlansAreRefusedAtFileAndLine) {
  struct Case {
    const char* yaml;
    const char* expect;  // in the message, after "plan.yaml:LINE: "
  } cases[] = {
      {"corridors:\n  - {name: c, centre: [[0, 0], [4, 0], [4, 3], [2, 3], [2, -2]], width_m: 1}\n",
       "plan.yaml:2: key 'corridors[0].centre': the corridor's walls intersect themselves"},
      {"rooms:\n  - name: r\n    polygon: [[0, 0], [4, 4], [4, 0], [0, 6]]\n",
       "plan.yaml:3: key 'rooms[0].polygon': the polygon intersects itself"},
      {"corridors:\n  - name: c\n    centre: [[0, 0], [4, 0]]\n    width_m: 0\n",
       "plan.yaml:4: key 'corridors[0].width_m': expected a width in (0, 50] m, got 0"},
      {"corridors:\n  - {name: c, centre: [[0, 0], [4, 0]], width_m: 2, walls: shiny}\n",
       "plan.yaml:2: key 'corridors[0].walls': expected one of default, plain, busy, bare, "
       "posters; got 'shiny'"},
      {"floor: posters\nrooms:\n  - {name: r, rect: [0, 0, 1, 1]}\n",
       "plan.yaml:1: key 'floor': 'posters' is a style for walls and boxes only"},
      {"corridors:\n  - {name: c, centre: [[0, 0], [4, 0]], width_m: 2}\nrooms:\n"
       "  - {name: r, rect: [0, 1.1, 4, 3]}\ndoors:\n"
       "  - between: [c, r]\n    at: [2, 2]\n    width_m: 1\n",
       "plan.yaml:7: key 'doors[0].at': the door at (2, 2) is on no wall of 'c'"},
      {"corridors:\n  - {name: c, centre: [[0, 0], [4, 0]], width_m: 2}\nrooms:\n"
       "  - {name: r, rect: [0, 1.1, 4, 3]}\ndoors:\n"
       "  - {between: [c, r], at: [3.8, 1.05], width_m: 1}\n",
       "plan.yaml:6: key 'doors[0]': the door (1 m wide at (3.8, 1.05)) runs past the end of "
       "wall 2 of 'c'"},
      {"corridors:\n  - {name: c, centre: [[0, 0], [4, 0]], width_m: 2}\nrooms:\n"
       "  - {name: r, rect: [1, 0.5, 3, 3]}\n",
       "plan.yaml:4: key 'rooms[0]': space 'r' overlaps space 'c'"},
      {"corridors:\n  - {name: c, centre: [[0, 0], [4, 0], [0, 0.5]], width_m: 1}\n",
       "plan.yaml:2: key 'corridors[0].centre': the turn at point 1 (4, 0) is sharper than 150"},
      {"rooms:\n  - {name: r, rect: [0, 0, 4, 4]}\nboxes:\n"
       "  - {name: b, at: [3.9, 2], size_m: [1, 1], height_m: 1}\n",
       "plan.yaml:4: key 'boxes[0]': the box's corner (4.4, 1.5) is outside every corridor"},
      {"rooms:\n  - {name: r, rect: [0, 0, 4, 4]}\nplaces:\n  start: [5, 5]\n",
       "plan.yaml:4: key 'places.start': the place (5, 5) is inside no corridor or room"},
      {"rooms:\n  - {name: r, rect: [0, 0, 4, 4], colour: red}\n",
       "plan.yaml:2: key 'rooms[0].colour': unknown key"},
      {"ceiling_height_m: 2.5\n", "plan.yaml:1: a floor plan needs at least one corridor"},
      {"rooms:\n  - {name: r, rect: [0, 0, 4, 4]}\nlights:\n  - {type: directional, cutoff_deg: "
       "30}\n",
       "plan.yaml:4: key 'lights[0].cutoff_deg': only a point light has a cone"},
      {"rooms:\n  - {name: r, rect: [0, 0, 4, 4]}\nlights:\n  - {type: point, cutoff_deg: 120}\n",
       "plan.yaml:4: key 'lights[0].cutoff_deg': expected an angle in (0, 90] degrees"},
  };
  for (const Case& c : cases) {
    sim::FloorPlan plan;
    std::string error;
    EXPECT_FALSE(sim::ParseFloorPlan(c.yaml, "plan.yaml", ".", &plan, &error)) << c.yaml;
    EXPECT_NE(error.find(c.expect), std::string::npos)
        << "got: " << error << "\nwant: " << c.expect;
  }
}

TEST(FloorPlanTest, AScenarioSaysFloorPlanAndItsSceneLoads) {
  TempDir dir("floor_plan");
  WriteText(dir / "plan.yaml",
            "corridors:\n  - {name: c, centre: [[0, 0], [6, 0]], width_m: 2}\nrooms:\n"
            "  - {name: r, rect: [2, 1.1, 5, 4]}\ndoors:\n"
            "  - {between: [c, r], at: [3.5, 1.05], width_m: 1.2, height_m: 2.1}\n"
            "boxes:\n  - {name: desk, at: [3.5, 3], size_m: [1, 0.5], height_m: 0.7}\n");
  const std::string base = "path:\n  - [0.5, 0]\n  - [3.5, 0]\n  - [3.5, 2.4]\n";
  WriteText(dir / "s.yaml", "floor_plan: plan.yaml\n" + base);
  sim::Scenario s;
  std::string error;
  ASSERT_TRUE(sim::LoadScenario(dir / "s.yaml", &s, &error)) << error;
  EXPECT_EQ(s.scene_path, dir / "plan.yaml");
  EXPECT_NE(sim::ScenarioToYaml(s).find("floor_plan: "), std::string::npos);
  // The generated scene loads with the robot and its walls are the path check's.
  mjModel* m = sim::LoadSceneModel(s.scene_path, &error);
  ASSERT_NE(m, nullptr) << error;
  EXPECT_GE(mj_name2id(m, mjOBJ_BODY, "robot"), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_GEOM, "wall-furniture_box_desk_0"), 0);
  mj_deleteModel(m);
  // Through the desk: refused with the desk's name.
  WriteText(dir / "s2.yaml",
            "floor_plan: plan.yaml\npath:\n  - [0.5, 0]\n  - [3.5, 0]\n  - [3.5, 3.5]\n");
  EXPECT_FALSE(sim::LoadScenario(dir / "s2.yaml", &s, &error));
  EXPECT_NE(error.find("box_desk"), std::string::npos) << error;
  // scene and floor_plan: one of them, at file:line.
  WriteText(dir / "s3.yaml", "scene: x.xml\nfloor_plan: plan.yaml\n" + base);
  EXPECT_FALSE(sim::LoadScenario(dir / "s3.yaml", &s, &error));
  EXPECT_NE(error.find("s3.yaml:2: key 'floor_plan': give scene (an MJCF file) or floor_plan"),
            std::string::npos)
      << error;
  WriteText(dir / "s4.yaml", "seed: 1\n" + base);
  EXPECT_FALSE(sim::LoadScenario(dir / "s4.yaml", &s, &error));
  EXPECT_NE(error.find("key 'scene': required"), std::string::npos) << error;
  // A route between two places of the plan: planned, and checked as any path.
  WriteText(dir / "plan.yaml",
            "corridors:\n  - {name: c, centre: [[0, 0], [6, 0]], width_m: 2}\nrooms:\n"
            "  - {name: r, rect: [2, 1.1, 5, 4]}\ndoors:\n"
            "  - {between: [c, r], at: [3.5, 1.05], width_m: 1.2, height_m: 2.1}\n"
            "places:\n  west: [0.6, 0]\n  room: [3.5, 3]\n");
  WriteText(dir / "s6.yaml", "floor_plan: plan.yaml\nroute: {from: west, to: room}\n");
  ASSERT_TRUE(sim::LoadScenario(dir / "s6.yaml", &s, &error)) << error;
  EXPECT_EQ(s.path.front(), Eigen::Vector2d(0.6, 0));
  EXPECT_EQ(s.path.back(), Eigen::Vector2d(3.5, 3));
  WriteText(dir / "s7.yaml", "floor_plan: plan.yaml\nroute:\n  from: west\n  to: attic\n");
  EXPECT_FALSE(sim::LoadScenario(dir / "s7.yaml", &s, &error));
  EXPECT_NE(error.find("s7.yaml:4: key 'route.to': no place 'attic'"), std::string::npos) << error;
  WriteText(dir / "s8.yaml", "scene: x.xml\nroute: {from: west, to: room}\n");
  EXPECT_FALSE(sim::LoadScenario(dir / "s8.yaml", &s, &error));
  EXPECT_NE(error.find("give floor_plan:"), std::string::npos) << error;
  // A bad plan is reported at the plan's file and line.
  WriteText(dir / "plan.yaml", "corridors:\n  - {name: c, centre: [[0, 0], [6, 0]], width_m: 0}\n");
  WriteText(dir / "s5.yaml", "floor_plan: plan.yaml\n" + base);
  EXPECT_FALSE(sim::LoadScenario(dir / "s5.yaml", &s, &error));
  EXPECT_NE(error.find("plan.yaml:2: key 'corridors[0].width_m'"), std::string::npos) << error;
}

double SegmentPointDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                            const Eigen::Vector2d& b) {
  const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (a + t * (b - a) - p).norm();
}

TEST(FloorPlanTest, APlannedPathKeepsTheFootprintInFreeSpace) {
  // From the corridor's west end into the room through its 1.2 m door, round the desk.
  const char* kPlan = R"(
corridors:
  - {name: c, centre: [[0, 0], [10, 0]], width_m: 2}
rooms:
  - {name: r, rect: [4, 1.1, 9, 6]}
doors:
  - {between: [c, r], at: [5, 1.05], width_m: DOOR, height_m: 2.1}
boxes:
  - {name: desk, at: [5.5, 3.2], size_m: [2.4, 0.8], height_m: 0.75}
)";
  auto plan_with_door = [&](const std::string& width) {
    std::string yaml = kPlan;
    yaml.replace(yaml.find("DOOR"), 4, width);
    return Parse(yaml);
  };
  const sim::FloorPlan plan = plan_with_door("1.2");
  const double clearance = 0.38;
  std::vector<Eigen::Vector2d> path;
  std::string error;
  ASSERT_TRUE(sim::PlanPath(plan, {0.6, 0}, {5.5, 4.8}, clearance, &path, &error)) << error;
  ASSERT_GE(path.size(), 3u);
  EXPECT_EQ(path.front(), Eigen::Vector2d(0.6, 0));
  EXPECT_EQ(path.back(), Eigen::Vector2d(5.5, 4.8));
  // Every point of every segment (every 1 cm) keeps the clearance from every wall piece, jamb
  // and box side, and lies in the corridor, the room or the door's passage.
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> walls;
  for (const sim::PlanSurface& s : sim::PlanSurfaces(plan)) {
    if (std::abs(s.y_axis.z()) < 0.5 || s.centre.z() - s.half_height_m > 1.5) continue;
    Eigen::Vector2d a, b;
    Ends(s, &a, &b);
    walls.emplace_back(a, b);
  }
  ASSERT_GT(walls.size(), 10u);
  const std::vector<Eigen::Vector2d> passage = {{4.4, 1}, {5.6, 1}, {5.6, 1.1}, {4.4, 1.1}};
  double closest = 1e9;
  for (size_t i = 1; i < path.size(); ++i) {
    const int n = static_cast<int>(std::ceil((path[i] - path[i - 1]).norm() / 0.01));
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector2d p = path[i - 1] + (path[i] - path[i - 1]) * (double(k) / n);
      for (const auto& [a, b] : walls) closest = std::min(closest, SegmentPointDistance(p, a, b));
      EXPECT_TRUE(sim::InsidePolygon(plan.spaces[0].polygon, p) ||
                  sim::InsidePolygon(plan.spaces[1].polygon, p) || sim::InsidePolygon(passage, p))
          << p.transpose();
    }
  }
  EXPECT_GE(closest, clearance - 1e-9);
  EXPECT_LT(closest, clearance + 0.2);  // it does go through the door, round the desk
  // Deterministic.
  std::vector<Eigen::Vector2d> again;
  ASSERT_TRUE(sim::PlanPath(plan, {0.6, 0}, {5.5, 4.8}, clearance, &again, &error));
  EXPECT_EQ(path, again);
  // A door narrower than the footprint: no path; an end in a wall's clearance: refused.
  EXPECT_FALSE(
      sim::PlanPath(plan_with_door("0.7"), {0.6, 0}, {5.5, 4.8}, clearance, &path, &error));
  EXPECT_NE(error.find("no path from (0.6, 0) to (5.5, 4.8)"), std::string::npos) << error;
  EXPECT_FALSE(sim::PlanPath(plan, {0.6, 0.8}, {5.5, 4.8}, clearance, &path, &error));
  EXPECT_NE(error.find("the start (0.6, 0.8) is not in free space"), std::string::npos) << error;
}

TEST(FloorPlanTest, TheMjcfIsDeterministic) {
  const char* yaml = R"(
corridors:
  - {name: c, centre: [[0, 0], [5, 0], [8, 3]], width_m: 2}
boxes:
  - {name: b, at: [2, 0.5], yaw_deg: 17, size_m: [0.5, 0.3], height_m: 1}
)";
  const std::string a = sim::FloorPlanToMjcf(Parse(yaml), "robot.xml");
  const std::string b = sim::FloorPlanToMjcf(Parse(yaml), "robot.xml");
  EXPECT_EQ(a, b);
  EXPECT_NE(a.find("<include file=\"robot.xml\"/>"), std::string::npos);
}

}  // namespace
