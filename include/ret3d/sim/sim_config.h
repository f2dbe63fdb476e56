// Scenario configuration of the simulator (config/sim/*.yaml): every knob of road layout, ground, clutter, traffic
// and materials, with the defaults of an urban street. Loading validates the file: an unknown key, a wrong type or an
// empty range is an error naming the file and the key.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace ret3d {
namespace sim {

// A closed interval [lo, hi] a value is drawn from uniformly.
struct Range {
  double lo = 0, hi = 0;
};

// Reflectivity of a surface material (drawn per object around `reflectivity` with `sigma`) and the extra probability
// that a ray hitting it returns nothing (glass, foliage).
struct MaterialConfig {
  double reflectivity = 0.2;
  double sigma = 0.03;
  double dropout = 0.0;
  double porosity = 0.0;  // Surface::porosity: returns scattered in depth inside the volume (vegetation)
};

struct RoadConfig {
  int lanes_per_direction = 1;
  double lane_width = 3.5;
  double bike_lane_width = 1.5;     // between the traffic lanes and the parking lane (0 = none)
  double parking_lane_width = 2.3;  // 0 = no parking
  double shoulder_width = 0.0;
  double median_width = 0.0;        // > 0: a concrete barrier on the centre line (highway)
  double sidewalk_width = 4.0;      // 0 = none (then no curb either)
  double curb_height = 0.15;
  Range segment_length{60, 160};    // straight and curved pieces of the main road
  double curve_probability = 0.4;
  Range curve_radius{60, 200};
  Range curve_angle_deg{15, 60};
  Range intersection_spacing{90, 180};  // 0..0 = no intersections
  double cross_road_length = 120;       // each side of the main road
  double margin = 160;                  // road before the ego start and after its furthest reach
  double marking_dash = 3.0, marking_gap = 6.0;
  double crosswalk_spacing = 120;       // mid-block pedestrian crossings (0 = none)
  // Hills: the drawn main road rises and falls along its length as a sine of this amplitude (m) and wavelength (m),
  // both drawn per scene; everything on or beside it follows its height and the sensor stays level, so the cars ahead
  // and behind stand above or below the flat ground (config/sim/hills.yaml). 0..0 = flat (nothing drawn).
  Range hill_amplitude{0, 0};
  Range hill_wavelength{150, 400};
};

struct GroundConfig {
  double grid_cell = 1.0;               // heightfield resolution (m)
  double road_roughness = 0.01;         // amplitude (m) of smooth noise on the carriageway
  double terrain_roughness = 0.05;      // and off the road
  double roughness_wavelength = 3.0;    // m
  double terrain_slope_max = 0.06;      // gentle slope away from the road beyond the sidewalk (rise / run)
  double terrain_step = 0.5;            // m between the sidewalk's outer edge and the start of the slope
};

struct ClutterConfig {
  double building_probability = 0.85;   // per frontage slot
  Range building_setback{0.5, 5.0};
  Range building_frontage{8, 28};
  Range building_depth{8, 18};
  Range building_height{5, 22};
  Range building_gap{1, 8};
  double wall_probability = 0.5;        // a wall or fence fills a gap between buildings
  Range wall_height{0.8, 2.2};
  double fence_fraction = 0.5;          // of those, fences (posts and rails) rather than solid walls
  Range tree_spacing{8, 22};            // along each side, in the furniture zone or beyond
  Range tree_trunk_radius{0.12, 0.3};
  Range tree_trunk_height{2.2, 4.0};
  Range tree_crown_radius{1.2, 3.0};
  Range pole_spacing{25, 45};
  Range pole_height{5, 9};
  Range sign_spacing{35, 90};
  double guard_rail = 0.0;              // 1: guard rails along the road edge (highway)
  double vegetation_setback = 0.0;      // trees this far beyond the sidewalk instead of in its furniture zone
  // Roadside clutter real scans are full of (drawn from their own random stream, so the rest of the scene does not
  // change when they are switched on): hedges along the sidewalk's outer edge, bushes beyond it, bollards at the curb.
  double hedge_probability = 0.0;       // per frontage slot
  Range hedge_height{0.8, 1.8};
  Range bush_spacing{0, 0};             // along each side; 0..0 = none
  Range bush_radius{0.4, 1.0};
  Range bollard_spacing{0, 0};          // along each side; 0..0 = none
  // The sizes of roadside structures (defaults: the sizes the simulator always drew). A range with lo == hi is not
  // drawn, so the defaults leave the scene of a seed unchanged.
  Range pole_radius{0.1, 0.1};          // street lights
  Range sign_height{2.3, 2.3};          // sign pole top above the kerb (m)
  Range sign_plate{0.6, 0.6};           // plate side (m)
  Range bollard_radius{0.08, 0.08};
  Range bollard_height{0.7, 1.1};       // above the kerb, plus 0.1 m
  // Street furniture drawn from a stream of its own (none by default): thin posts (parking meters, pipes, posts of
  // ticket machines), groups of parked bicycles (unlabelled: KITTI labels no bicycle without a rider), pedestrian
  // railings along the kerb and low walls or planters at the sidewalk's outer edge.
  Range post_spacing{0, 0};             // along each side; 0..0 = none
  Range post_radius{0.03, 0.08};
  Range post_height{1.0, 3.0};
  Range bicycle_spacing{0, 0};          // groups of 1-4 parked bicycles; 0..0 = none
  double railing_probability = 0.0;     // per frontage slot: a railing at the kerb
  Range railing_height{0.9, 1.2};
  double low_wall_probability = 0.0;    // per frontage slot: a low wall or planter at the sidewalk's outer edge
  Range low_wall_height{0.2, 0.7};
};

// A group of car colours: its share of cars and the range (uniform) of its paint's reflectivity at 905 nm.
struct PaintMode {
  double weight = 1.0;
  Range reflectivity{0.3, 0.4};
};

// Stop-and-go queues: in a sequence drawn as a queue, the ego starts standing behind a vehicle in its lane, with
// queues ahead of and behind it in every lane of its direction; queued vehicles creep and stop.
struct QueueConfig {
  double probability = 0.0;             // fraction of sequences that start in a queue (0 = none)
  Range ahead{4, 10};                   // vehicles ahead of the ego in each lane of its direction
  Range behind{1, 4};                   // and behind it
  Range gap{1.0, 4.0};                  // bumper to bumper at standstill (m): the IDM jam distance of queued vehicles
  Range speed{0.3, 3.0};                // creeping speed (m/s)
  double stop_probability = 0.5;        // a new target speed of a queued vehicle is a stop
  double headway = 0.8;                 // IDM time headway of queued vehicles (s)
};

struct TrafficConfig {
  Range ego_speed{0, 15};               // m/s
  double ego_lane = -1;                 // -1 = random lane of the ego direction, else lane index from the centre
  double car_density = 2.5;             // moving cars per 100 m per lane
  Range car_speed{6, 14};
  double parked_probability = 0.6;      // per parking slot (6 m)
  double parked_on_cross_roads = 1.0;   // 1: cross roads get parked cars too
  double pedestrian_density = 8.0;      // per 100 m of sidewalk (both sides counted separately)
  Range pedestrian_speed{0.5, 2.0};
  double pedestrian_standing = 0.2;     // fraction standing still
  double pedestrian_crossing = 0.25;    // fraction that crosses the road ahead of them
  double cyclist_density = 1.5;         // per 100 m of bike lane (or shoulder)
  Range cyclist_speed{3, 8};
  double turn_probability = 0.3;        // moving cars that turn right at the next intersection
  Range speed_change_interval{3, 10};   // s between new target speeds
  double stop_probability = 0.1;        // chance a new target speed is a stop (0 m/s for a while)
  double traffic_light_cycle = 30.0;    // s; main road and cross road green alternate; 0 = no lights
  double sedan = 0.4, hatchback = 0.25, suv = 0.25, van = 0.1;  // body type mix of Car
  // Vehicles of KITTI's other classes, as fractions of all moving, parked and queued vehicles: box trucks (labelled
  // Truck) and delivery vans (labelled Van), which KITTI-style training ignores for Car.
  double truck = 0.0, delivery_van = 0.0;
  QueueConfig queue;
};

struct SimConfig {
  std::string name = "urban";
  std::string source;                   // file it was read from
  std::string sensor = "hdl64e";        // default sensor model (config/sensors/<sensor>.yaml)
  double frame_rate = 10.0;
  double label_range = 80.0;            // objects beyond this distance are not labelled
  int label_min_points = 1;             // nor those with fewer returns
  // Per-sequence mounting error of the sensor (Gaussian sigma; drawn from the sequence's own stream, labels stay in the
  // tilted LiDAR frame): height (m) and pitch and roll (degrees).
  double mount_height_jitter = 0.0;
  double mount_tilt_jitter_deg = 0.0;
  RoadConfig road;
  GroundConfig ground;
  ClutterConfig clutter;
  TrafficConfig traffic;
  std::map<std::string, MaterialConfig> materials;  // see defaultMaterials()
  // Car paint: per car, a mode drawn by weight, then a reflectivity uniformly in its range (spread by the `paint`
  // material's sigma is not applied). Empty = the `paint` material for every car.
  std::vector<PaintMode> paint;
};

// The material table every scene uses (asphalt, marking, concrete, curb, terrain, building, glass, foliage, bark,
// metal, sign, paint, car_glass, tire, plate, skin, clothing); a config may override any entry.
std::map<std::string, MaterialConfig> defaultMaterials();

// Reads a scenario file; throws std::runtime_error naming the file and key on bad input.
SimConfig loadSimConfig(const std::string& path);

}  // namespace sim
}  // namespace ret3d
