// Triangle meshes of the actors: cars of four body types, an articulated walking pedestrian and a cyclist (bike plus
// pedalling rider). Each mesh is in the actor's frame: origin on the ground below the box centre, x forward, z up;
// it stays inside the box (length x width x height) the labeller would draw around it, with `kLabelMargin` to spare
// on every side so range noise does not push returns out of the box.
#pragma once

#include <string>

#include "ret3d/sim/mesh.h"

namespace ret3d {
namespace sim {

// Gap between a mesh and its label box on each side (m): about two range-noise sigmas.
inline constexpr double kLabelMargin = 0.05;

// Truck: a box truck (a cab lower than its cargo box), for KITTI's Truck class.
enum class CarBody { Sedan = 0, Hatchback = 1, Suv = 2, Van = 3, Truck = 4 };
const char* bodyName(CarBody b);

struct ActorSurfaces {
  Surface paint, glass, tire, plate, skin, clothing, clothing2, metal;
};

// A car whose mesh fills the box length x width x height (minus the margin): body, glazed cabin, wheels, plates.
TriangleMesh carMesh(CarBody body, double length, double width, double height, const ActorSurfaces& s);

// A person's build: `stature` tall, `breadth` across the shoulders (arms included), `depth` from chest to back
// (clothes included), and whether a backpack is worn.
struct PersonShape {
  double stature = 1.75, breadth = 0.45, depth = 0.27;
  bool backpack = false;
};

// A person of build `p` walking at gait phase `phase` (radians; one period is two steps) with hip swing `swing`
// (radians, 0 = standing). Origin between the feet.
TriangleMesh pedestrianMesh(const PersonShape& p, double phase, double swing, const ActorSurfaces& s);

// A cyclist's build: the bicycle `length` long (wheels included, plus the label margin at each end) with handlebars
// `bar_width` across (road bikes about 0.40 m, city and mountain bikes 0.55-0.72), a rider of `stature` whose torso
// is `breadth` across and leans `lean` radians forward of vertical (0.3 upright on a city bike, 0.9 on a road bike).
struct RiderShape {
  double length = 1.78, stature = 1.76, bar_width = 0.54, breadth = 0.34, lean = 0.75;
};

// A bicycle and rider of build `r`, crank at angle `crank` (radians). Origin on the ground at the middle of the
// wheelbase.
TriangleMesh cyclistMesh(const RiderShape& r, double crank, const ActorSurfaces& s);
// A parked bicycle without a rider, `length` long with handlebars `bar_width` across, in the same frame.
TriangleMesh bicycleMesh(double length, double bar_width, const ActorSurfaces& s);

}  // namespace sim
}  // namespace ret3d
