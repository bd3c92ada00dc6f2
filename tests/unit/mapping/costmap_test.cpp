#include "semap/mapping/costmap.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <set>
#include <string>

namespace semap::mapping {
namespace {

// The simulated world's classes (config/sim-classes.yaml).
enum Class : std::int32_t {
  kFree = 0,
  kRoad,
  kSidewalk,
  kBuilding,
  kPole,
  kVegetation,
  kTerrain,
  kCar,
  kClasses
};

// S-CSM maps: a point adds evidence to its own cell only, so every test places cells exactly.
MapParams csm_params(float resolution = 0.2f) {
  MapParams p;
  p.method = MapMethod::kCsm;
  p.resolution = resolution;
  p.num_classes = kClasses;
  return p;
}

// config/costmap-example.yaml's costs, a 4 m x 4 m window at the map's 0.2 m.
CostmapParams street_costs() {
  CostmapParams p;
  p.width_m = 4.0;
  p.height_m = 4.0;
  p.class_cost = {0, 0, 0, 100, 100, 70, 40, 100};
  p.ground_class = {false, true, true, false, false, false, true, false};
  return p;
}

// Training points placed by hand, inserted as one training set.
class Scene {
 public:
  // `count` points of one class at one position.
  Scene& add(float x, float y, float z, std::int32_t label, int count = 3) {
    for (int i = 0; i < count; ++i) {
      hard_points_.emplace_back(x, y, z);
      hard_labels_.push_back(label);
    }
    return *this;
  }
  // One point of a soft label: an occupied cell whose class the map is unsure of.
  Scene& add_soft(float x, float y, float z, const std::vector<float>& probabilities) {
    soft_points_.emplace_back(x, y, z);
    probabilities_.insert(probabilities_.end(), probabilities.begin(), probabilities.end());
    return *this;
  }
  SemanticMap map(const MapParams& params = csm_params()) const {
    // A training set holds its soft rows for its first points.
    TrainingSet set;
    set.num_classes = params.num_classes;
    set.points = soft_points_;
    set.labels.assign(soft_points_.size(), TrainingSet::kSoft);
    set.probabilities = probabilities_;
    set.points.insert(set.points.end(), hard_points_.begin(), hard_points_.end());
    set.labels.insert(set.labels.end(), hard_labels_.begin(), hard_labels_.end());
    set.num_hits = set.points.size();
    SemanticMap map(params);
    map.insert(set);
    return map;
  }

 private:
  std::vector<Eigen::Vector3f> soft_points_;
  std::vector<float> probabilities_;
  std::vector<Eigen::Vector3f> hard_points_;
  std::vector<std::int32_t> hard_labels_;
};

// The cost at (x, y), through the OccupancyGrid convention alone.
int cost_at(const Costmap& costmap, double x, double y) {
  const auto col = static_cast<int>(std::floor((x - costmap.origin_x()) / costmap.resolution));
  const auto row = static_cast<int>(std::floor((y - costmap.origin_y()) / costmap.resolution));
  return costmap.data.at(static_cast<std::size_t>(row * costmap.width + col));
}

int count_known(const Costmap& costmap) {
  int known = 0;
  for (const std::int8_t v : costmap.data) known += v != -1 ? 1 : 0;
  return known;
}

const Eigen::Vector2d kCentre(0.0, 0.0);

TEST(Costmap, RoadColumnIsFreeToDrive) {
  auto map = Scene().add(0.1f, 0.1f, 0.1f, kRoad).map();
  const Costmap costmap = build_costmap(map, street_costs(), kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 0);
  EXPECT_EQ(count_known(costmap), 1);  // rule 5e: the rest is unknown
}

TEST(Costmap, CarColumnIsLethalWithOrWithoutGround) {
  auto map = Scene()
                 .add(0.1f, 0.1f, 0.1f, kRoad)
                 .add(0.1f, 0.1f, 0.7f, kCar)   // a car on the road
                 .add(1.1f, 0.1f, 0.7f, kCar)   // a car with no ground seen: its own ground
                 .add(1.5f, 0.1f, 0.1f, kRoad)  // road next to it
                 .map();
  const Costmap costmap = build_costmap(map, street_costs(), kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 100);
  EXPECT_EQ(cost_at(costmap, 1.1, 0.1), 100);
  EXPECT_EQ(cost_at(costmap, 1.5, 0.1), 0);
}

TEST(Costmap, VegetationAboveRoadCostsItsClass) {
  auto map = Scene().add(0.1f, 0.1f, 0.1f, kRoad).add(0.1f, 0.1f, 1.1f, kVegetation).map();
  EXPECT_EQ(cost_at(build_costmap(map, street_costs(), kCentre), 0.1, 0.1), 70);
}

TEST(Costmap, TerrainCostsItsClassAndIsGround) {
  // Terrain (40) is the ground; a car 3 m above it is over the band, a bush at 1 m is in it.
  auto map = Scene()
                 .add(0.1f, 0.1f, 0.1f, kTerrain)
                 .add(0.1f, 0.1f, 3.1f, kCar)
                 .add(0.3f, 0.1f, 0.1f, kTerrain)
                 .add(0.3f, 0.1f, 1.1f, kVegetation)
                 .map();
  const Costmap costmap = build_costmap(map, street_costs(), kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 40);
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), 70);
}

TEST(Costmap, OverhangAboveTheBandIsIgnoredAndTheBandEdgesCount) {
  // Columns of road at z 0.1 (cell 0) with a building cell k cells above: the band is
  // 0.1 .. 2.0 m between centres, i.e. cells 1 .. 10 above the ground at 0.2 m.
  Scene scene;
  const int above[] = {1, 10, 11, 20};
  for (int i = 0; i < 4; ++i) {
    const float x = 0.1f + 0.2f * static_cast<float>(i);
    scene.add(x, 0.1f, 0.1f, kRoad)
        .add(x, 0.1f, 0.1f + 0.2f * static_cast<float>(above[i]), kBuilding);
  }
  auto map = scene.map();
  const Costmap costmap = build_costmap(map, street_costs(), kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 100);  // 0.2 m above
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), 100);  // 2.0 m above: on the band's top edge
  EXPECT_EQ(cost_at(costmap, 0.5, 0.1), 0);    // 2.2 m: a bridge the robot passes under
  EXPECT_EQ(cost_at(costmap, 0.7, 0.1), 0);    // 4.0 m
}

TEST(Costmap, CellsBelowMinHeightAreIgnored) {
  auto map = Scene()
                 .add(0.1f, 0.1f, 0.1f, kRoad)
                 .add(0.1f, 0.1f, 0.3f, kVegetation)  // 0.2 m above the road
                 .add(0.3f, 0.1f, 0.1f, kRoad)
                 .add(0.3f, 0.1f, 0.5f, kVegetation)  // 0.4 m above
                 .map();
  CostmapParams p = street_costs();
  p.min_height_m = 0.3;
  const Costmap costmap = build_costmap(map, p, kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 0);
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), 70);
}

TEST(Costmap, GroundIsTheLowestGroundClassCellAndConfigurable) {
  // A car cell 2.2 m below the road (a car on a lower street seen through a gap): with road
  // as ground it is below the ground and ignored; with no ground classes the car is the
  // ground and the road 2.2 m above it is outside its band, so the column is the car's.
  auto map = Scene().add(0.1f, 0.1f, 0.1f, kRoad).add(0.1f, 0.1f, -2.1f, kCar).map();
  CostmapParams p = street_costs();
  EXPECT_EQ(cost_at(build_costmap(map, p, kCentre), 0.1, 0.1), 0);
  p.ground_class.assign(kClasses, false);
  EXPECT_EQ(cost_at(build_costmap(map, p, kCentre), 0.1, 0.1), 100);
}

TEST(Costmap, FreeSpaceOnlyIsZeroAndNothingObservedIsUnknown) {
  auto map = Scene().add(0.1f, 0.1f, 0.5f, kFree).add(0.1f, 0.1f, 0.9f, kFree).map();
  const Costmap costmap = build_costmap(map, street_costs(), kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 0);
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), -1);
  EXPECT_EQ(cost_at(costmap, -1.9, -1.9), -1);
  EXPECT_EQ(count_known(costmap), 1);
}

TEST(Costmap, FreeCellAboveAnObstacleDoesNotClearIt) {
  auto map = Scene().add(0.1f, 0.1f, 0.5f, kCar).add(0.1f, 0.1f, 0.9f, kFree).map();
  EXPECT_EQ(cost_at(build_costmap(map, street_costs(), kCentre), 0.1, 0.1), 100);
}

TEST(Costmap, UncertainOccupiedCellIsUnknownNotFree) {
  // Column (0.1, 0.1): free space and one unsure car-ish cell. Column (0.3, 0.1): road with
  // the unsure cell above it. Column (0.5, 0.1): the same plus a certain building: lethal wins.
  const std::vector<float> unsure = {0, 0.3f, 0, 0.3f, 0, 0, 0, 0.4f};  // car 0.4
  auto map = Scene()
                 .add(0.1f, 0.1f, 1.5f, kFree)
                 .add_soft(0.1f, 0.1f, 0.5f, unsure)
                 .add(0.3f, 0.1f, 0.1f, kRoad)
                 .add_soft(0.3f, 0.1f, 0.5f, unsure)
                 .add(0.5f, 0.1f, 0.1f, kRoad)
                 .add_soft(0.5f, 0.1f, 0.5f, unsure)
                 .add(0.5f, 0.1f, 0.9f, kBuilding)
                 .map();
  const auto cell = map.query(Eigen::Vector3f(0.1f, 0.1f, 0.5f));
  ASSERT_TRUE(cell.has_value());
  ASSERT_EQ(cell->argmax(), kCar);
  ASSERT_GT(cell->variance(kCar), 0.02f);  // the default max_variance

  CostmapParams p = street_costs();
  Costmap costmap = build_costmap(map, p, kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), -1);
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), -1);
  EXPECT_EQ(cost_at(costmap, 0.5, 0.1), 100);
  // Without the threshold the cell is a car like any other.
  p.max_variance = 0.0;
  costmap = build_costmap(map, p, kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 100);
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), 100);
}

TEST(Costmap, MapUnknownVarianceHidesACellAltogether) {
  // The map's own unknown_variance makes the unsure cell unknown (rule 1): the column has
  // only free space left.
  MapParams params = csm_params();
  params.unknown_variance = 0.02f;
  auto map = Scene()
                 .add(0.1f, 0.1f, 1.5f, kFree)
                 .add_soft(0.1f, 0.1f, 0.5f, {0, 0.3f, 0, 0.3f, 0, 0, 0, 0.4f})
                 .map(params);
  EXPECT_EQ(cost_at(build_costmap(map, street_costs(), kCentre), 0.1, 0.1), 0);
}

TEST(Costmap, ClassOfCostMinusOneIsUnknown) {
  auto map = Scene().add(0.1f, 0.1f, 0.1f, kRoad).add(0.1f, 0.1f, 0.5f, kPole).map();
  CostmapParams p = street_costs();
  p.class_cost[kPole] = -1;
  EXPECT_EQ(cost_at(build_costmap(map, p, kCentre), 0.1, 0.1), -1);
}

TEST(Costmap, CoarserCostmapAggregatesTheMapColumnsWhoseCentreFallsInACell) {
  // Map 0.1 m, costmap 0.2 m: costmap cell (0, 0) holds map columns x, y in {0.05, 0.15}.
  auto map = Scene()
                 .add(0.05f, 0.05f, 0.05f, kRoad)
                 .add(0.15f, 0.15f, 0.05f, kRoad)
                 .add(0.15f, 0.15f, 0.55f, kVegetation)  // one of four columns: the cell's max
                 .add(0.25f, 0.05f, 0.05f, kSidewalk)    // next costmap cell
                 .add(0.25f, 0.05f, 0.45f, kCar)
                 .add(0.45f, 0.05f, 0.05f, kRoad)  // costmap cell (2, 0)
                 .map(csm_params(0.1f));
  const Costmap costmap = build_costmap(map, street_costs(), kCentre);
  EXPECT_EQ(cost_at(costmap, 0.1, 0.1), 70);
  EXPECT_EQ(cost_at(costmap, 0.3, 0.1), 100);
  EXPECT_EQ(cost_at(costmap, 0.5, 0.1), 0);
  EXPECT_EQ(count_known(costmap), 3);
}

TEST(Costmap, CellsOfUnalignedResolutionsGoWhereTheirCentreIs) {
  // Map 0.2 m, costmap 0.3 m: columns [0, 0.2), [0.2, 0.4), [0.4, 0.6), [0.6, 0.8) have their
  // centre in costmap cells 0, 1, 1, 2 ([0, 0.3), [0.3, 0.6), [0.6, 0.9)); the second column
  // overlaps cell 0 too, but belongs to cell 1 only.
  auto map = Scene()
                 .add(0.1f, 0.1f, 0.1f, kRoad)
                 .add(0.3f, 0.1f, 0.1f, kVegetation)
                 .add(0.5f, 0.1f, 0.1f, kTerrain)
                 .add(0.7f, 0.1f, 0.1f, kSidewalk)
                 .map();
  CostmapParams p = street_costs();
  p.resolution = 0.3;
  const Costmap costmap = build_costmap(map, p, kCentre);
  EXPECT_EQ(cost_at(costmap, 0.15, 0.15), 0);
  EXPECT_EQ(cost_at(costmap, 0.45, 0.15), 70);
  EXPECT_EQ(cost_at(costmap, 0.75, 0.15), 0);
}

TEST(Costmap, RowMajorFromTheLowestYWithTheOriginAtTheCornerOfCellZero) {
  // A window 4 m wide and 2 m high around (10.3, -5.1): 20 x 10 cells; the centre's cell
  // (51, -26) is cell (10, 5), so cell (0, 0) is lattice cell (41, -31), corner (8.2, -6.2).
  auto map = Scene().add(11.05f, -4.55f, 0.1f, kCar).add(9.45f, -6.15f, 0.1f, kRoad).map();
  CostmapParams p = street_costs();
  p.width_m = 4.0;
  p.height_m = 2.0;
  const Costmap costmap = build_costmap(map, p, Eigen::Vector2d(10.3, -5.1));
  ASSERT_EQ(costmap.width, 20);
  ASSERT_EQ(costmap.height, 10);
  EXPECT_NEAR(costmap.origin_x(), 8.2, 1e-9);
  EXPECT_NEAR(costmap.origin_y(), -6.2, 1e-9);
  ASSERT_EQ(costmap.data.size(), 200u);
  // (11.05, -4.55): column (11.05 - 8.2) / 0.2 = 14, row (-4.55 + 6.2) / 0.2 = 8.
  EXPECT_EQ(costmap.data[8 * 20 + 14], 100);
  EXPECT_EQ(costmap.at(14, 8), 100);
  // (9.45, -6.15): column 6, row 0.
  EXPECT_EQ(costmap.data[0 * 20 + 6], 0);
  EXPECT_EQ(count_known(costmap), 2);
}

TEST(Costmap, WholeMapCoversEveryBlock) {
  // Blocks are 0.8 m (4 cells of 0.2 m): a point at (-0.7, 2.5) lies in block x -1, y 3 and one
  // at (1.7, 0.1) in block x 2, y 0: blocks x -1..2, y 0..3, i.e. 16 x 16 costmap cells from
  // lattice cell (-4, 0).
  auto map = Scene().add(-0.7f, 2.5f, 0.1f, kCar).add(1.7f, 0.1f, 0.1f, kRoad).map();
  CostmapParams p = street_costs();
  p.width_m = 0.0;
  p.height_m = 0.0;
  const Costmap costmap = build_costmap(map, p, Eigen::Vector2d(100.0, 100.0));
  EXPECT_EQ(costmap.first_x, -4);
  EXPECT_EQ(costmap.first_y, 0);
  EXPECT_EQ(costmap.width, 16);
  EXPECT_EQ(costmap.height, 16);
  EXPECT_EQ(cost_at(costmap, -0.7, 2.5), 100);
  EXPECT_EQ(cost_at(costmap, 1.7, 0.1), 0);
  EXPECT_EQ(count_known(costmap), 2);
}

TEST(Costmap, RejectsLogOddsMapsAndBadParameters) {
  MapParams logodds = csm_params();
  logodds.method = MapMethod::kLogOdds;
  const EvidenceGrid grid(logodds.cells_per_side(), kClasses);
  EXPECT_THROW(build_costmap(grid, logodds, street_costs(), kCentre), std::invalid_argument);
  auto map = Scene().add(0.1f, 0.1f, 0.1f, kRoad).map();
  CostmapParams p = street_costs();
  p.class_cost.pop_back();
  EXPECT_THROW(build_costmap(map, p, kCentre), std::invalid_argument);
  p = street_costs();
  p.width_m = 0.0;
  EXPECT_THROW(build_costmap(map, p, kCentre), std::invalid_argument);
  p = street_costs();
  p.class_cost[kCar] = 101;
  EXPECT_THROW(build_costmap(map, p, kCentre), std::invalid_argument);
}

// ---- configuration

ClassPalette sim_palette() {
  return load_palette(std::string(SEMAP_SOURCE_DIR) + "/config/sim-classes.yaml", kClasses);
}

TEST(CostmapConfig, ReadsTheExampleFile) {
  const auto root = common::ConfigSection::load_file(std::string(SEMAP_SOURCE_DIR) +
                                                     "/config/costmap-example.yaml");
  const auto section = root.section("costmap");
  const CostmapParams p = costmap_params_from_config(section, sim_palette());
  section.finish();
  EXPECT_DOUBLE_EQ(p.resolution, 0.2);
  EXPECT_DOUBLE_EQ(p.width_m, 40.0);
  EXPECT_DOUBLE_EQ(p.height_m, 40.0);
  EXPECT_DOUBLE_EQ(p.min_height_m, 0.1);
  EXPECT_DOUBLE_EQ(p.max_height_m, 2.0);
  EXPECT_DOUBLE_EQ(p.max_variance, 0.02);
  EXPECT_EQ(p.class_cost, street_costs().class_cost);
  EXPECT_EQ(p.ground_class, street_costs().ground_class);
}

TEST(CostmapConfig, UnlistedClassesAreLethalAndGroundDefaultsToCostZero) {
  const auto root = common::ConfigSection::load_string("costs: {road: 0, terrain: 40}\n");
  const CostmapParams p = costmap_params_from_config(root, sim_palette());
  EXPECT_EQ(p.class_cost, (std::vector<std::int8_t>{0, 0, 100, 100, 100, 100, 40, 100}));
  EXPECT_EQ(p.ground_class,
            (std::vector<bool>{false, true, false, false, false, false, false, false}));
  EXPECT_DOUBLE_EQ(p.width_m, CostmapParams{}.width_m);
}

std::string config_error(const std::string& yaml) {
  try {
    const auto root = common::ConfigSection::load_string(yaml, "robot.yaml");
    costmap_params_from_config(root.section("costmap"), sim_palette());
  } catch (const common::ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CostmapConfig, ErrorsNameTheFileLineAndKey) {
  using testing::HasSubstr;
  const std::string unknown = config_error("costmap:\n  costs:\n    road: 0\n    carr: 100\n");
  EXPECT_THAT(unknown, HasSubstr("robot.yaml:4: key 'costmap.costs.carr'"));
  EXPECT_THAT(unknown, HasSubstr("not a class name"));
  EXPECT_THAT(unknown, HasSubstr("vegetation"));  // the classes it could have meant
  EXPECT_THAT(config_error("costmap:\n  costs:\n    road: 0\n    car: 101\n"),
              HasSubstr("robot.yaml:4: key 'costmap.costs.car': cost 101 outside -1..100"));
  EXPECT_THAT(config_error("costmap:\n  costs:\n    car: -2\n"),
              HasSubstr("robot.yaml:3: key 'costmap.costs.car'"));
  EXPECT_THAT(config_error("costmap:\n  costs:\n    car: 99.5\n"),
              HasSubstr("key 'costmap.costs.car': expected an integer"));
  EXPECT_THAT(config_error("costmap:\n  costs:\n    free: 0\n"),
              HasSubstr("key 'costmap.costs.free': class 0 is free space"));
  EXPECT_THAT(config_error("costmap:\n  ground: [road,\n    grass]\n"),
              HasSubstr("robot.yaml:3: key 'costmap.ground': element 1: 'grass' is not a class"));
  EXPECT_THAT(config_error("costmap:\n  width_m: 0\n"), HasSubstr("key 'costmap.width_m'"));
  EXPECT_THAT(config_error("costmap:\n  min_height_m: 1\n  max_height_m: 0.5\n"),
              HasSubstr("robot.yaml:3: key 'costmap.max_height_m'"));
  EXPECT_THAT(config_error("costmap:\n  resolution: 0\n"), HasSubstr("key 'costmap.resolution'"));
  EXPECT_THAT(config_error("costmap:\n  max_variance: 0.5\n"),
              HasSubstr("key 'costmap.max_variance'"));
}

// ---- updates

TEST(CostmapUpdate, CoversExactlyTheChangedCells) {
  Costmap before;
  before.resolution = 0.2;
  before.width = 10;
  before.height = 8;
  before.data.assign(80, -1);
  Costmap after = before;
  EXPECT_TRUE(costmap_update(before, after)->empty());
  after.data[2 * 10 + 3] = 100;  // (3, 2)
  after.data[5 * 10 + 7] = 40;   // (7, 5)
  const auto update = costmap_update(before, after);
  ASSERT_TRUE(update.has_value());
  EXPECT_EQ(update->x, 3);
  EXPECT_EQ(update->y, 2);
  EXPECT_EQ(update->width, 5);
  EXPECT_EQ(update->height, 4);
  ASSERT_EQ(update->data.size(), 20u);
  EXPECT_EQ(update->data[0], 100);         // (3, 2)
  EXPECT_EQ(update->data[3 * 5 + 4], 40);  // (7, 5)
  EXPECT_EQ(update->data[1 * 5 + 1], -1);  // (4, 3): unchanged, inside the rectangle
  Costmap moved = after;
  moved.first_x += 1;
  EXPECT_FALSE(costmap_update(before, moved).has_value());
}

// Writes an update into a costmap, as a reader of map_msgs/OccupancyGridUpdate does.
void apply(Costmap& costmap, const CostmapUpdate& update) {
  for (int y = 0; y < update.height; ++y) {
    for (int x = 0; x < update.width; ++x) {
      costmap.data[static_cast<std::size_t>((update.y + y) * costmap.width + update.x + x)] =
          update.data[static_cast<std::size_t>(y * update.width + x)];
    }
  }
}

// Random scans of a cluttered 6 m x 6 m patch seen from above, classes at random.
common::LabeledCloud random_scan(std::mt19937& rng, Eigen::Vector3f& origin) {
  std::uniform_real_distribution<float> xy(-3.0f, 3.0f), z(-0.3f, 2.8f), u(0.0f, 1.0f);
  std::uniform_int_distribution<int> label(1, kClasses - 1);
  common::LabeledCloud cloud;
  cloud.num_classes = kClasses;
  origin = Eigen::Vector3f(xy(rng), xy(rng), 3.0f);
  const Eigen::Vector3f patch(xy(rng), xy(rng), 0.0f);
  for (int i = 0; i < 150; ++i) {
    // Ground with some clutter over it, in a 2 m patch, so each scan changes part of the map.
    const bool ground = u(rng) < 0.5f;
    const Eigen::Vector3f offset(2.0f * u(rng) - 1.0f, 2.0f * u(rng) - 1.0f, 0.0f);
    cloud.points.push_back(patch + offset + Eigen::Vector3f(0, 0, ground ? 0.05f : z(rng)));
    cloud.labels.push_back(
        static_cast<std::uint16_t>(ground ? (u(rng) < 0.5f ? kRoad : kTerrain) : label(rng)));
  }
  return cloud;
}

void expect_incremental_equals_full(const MapParams& params, const CostmapParams& p,
                                    unsigned seed) {
  std::mt19937 rng(seed);
  SemanticMap map(params);
  const Eigen::Vector2d centre(0.3, -0.2);
  Costmap live = build_costmap(map, p, centre);
  std::set<int> values_seen;
  int updates_with_changes = 0;
  for (int scan = 0; scan < 25; ++scan) {
    Eigen::Vector3f origin;
    const common::LabeledCloud cloud = random_scan(rng, origin);
    const InsertResult result = map.insert(cloud, origin);
    const Costmap previous = live;
    const CostmapUpdate update = update_costmap(live, map, p, result.updated_blocks);
    const Costmap full = build_costmap(map, p, centre);
    ASSERT_EQ(live, full) << "scan " << scan;
    // The update is exactly the difference, and applied to the old costmap gives the new one.
    const auto expected = costmap_update(previous, full);
    ASSERT_TRUE(expected.has_value());
    EXPECT_EQ(update.x, expected->x);
    EXPECT_EQ(update.y, expected->y);
    EXPECT_EQ(update.width, expected->width);
    EXPECT_EQ(update.height, expected->height);
    EXPECT_EQ(update.data, expected->data);
    Costmap patched = previous;
    apply(patched, update);
    EXPECT_EQ(patched, full);
    updates_with_changes += update.empty() ? 0 : 1;
    for (const std::int8_t v : full.data) values_seen.insert(v);
  }
  // The maps were rich enough to test something: several costs and most updates changing cells.
  EXPECT_GE(values_seen.size(), 4u);
  EXPECT_GE(updates_with_changes, 20);
}

TEST(CostmapUpdate, IncrementalEqualsFullRebuildOnRandomBkiMaps) {
  MapParams params;
  params.num_classes = kClasses;
  params.resolution = 0.1f;
  params.free_res = 0.3f;
  CostmapParams p = street_costs();
  p.width_m = 7.0;
  p.height_m = 6.0;
  p.resolution = 0.25;  // not a multiple of the map's 0.1 m
  expect_incremental_equals_full(params, p, 1);
  p.resolution = 0.1;
  expect_incremental_equals_full(params, p, 2);
}

TEST(CostmapUpdate, IncrementalEqualsFullRebuildOnRandomCsmMaps) {
  MapParams params = csm_params(0.2f);
  params.free_res = 0.3f;
  CostmapParams p = street_costs();
  p.width_m = 5.0;  // smaller than the scans: blocks outside the window are skipped
  p.height_m = 5.0;
  p.resolution = 0.4;
  expect_incremental_equals_full(params, p, 3);
}

TEST(CostmapUpdate, BlocksOutsideTheWindowChangeNothing) {
  auto map = Scene().add(0.1f, 0.1f, 0.1f, kRoad).map();
  Costmap costmap = build_costmap(map, street_costs(), kCentre);
  const Costmap before = costmap;
  const std::vector<common::BlockIndex> far = {{100, 100, 0}};
  EXPECT_TRUE(update_costmap(costmap, map, street_costs(), far).empty());
  EXPECT_EQ(costmap, before);
  CostmapParams other = street_costs();
  other.resolution = 0.1;
  EXPECT_THROW(update_costmap(costmap, map, other, far), std::invalid_argument);
}

}  // namespace
}  // namespace semap::mapping
