#pragma once
// Fanuc 30i tool centre point control for 5-axis machining (A-79348E): the machine configuration parameters
// and the offsets cnccomp updates from the measured pivot (rotary-axis position) errors.
//
//   19680 mechanical unit type: 0 no rotary axis, 2 two tool rotary axes, 12 two table rotary axes,
//         21 one tool (first) + one table (second) rotary axis. A single rotary head or table is written as
//         type 2 / 12 with a hypothetical second axis at 0 deg (19696 bit 1).
//   19681/19686 controlled-axis number of the first/second rotary axis (0 = hypothetical)
//   19682/19687 its axis direction: 1 X, 2 Y, 3 Z (machine coordinates, rotary axes at 0)
//   19684/19689 its rotation direction: 0 right-hand about +axis, 1 left-hand (for a positive command)
//   19685/19690 angle of a hypothetical axis (deg)
//   19697 reference tool axis direction (1 X, 2 Y, 3 Z; the tool tip points to the negative side)
//   19700-19702 rotary table position: machine coordinates of a point on the first table rotary axis
//   19703-19705 intersection offset vector between the first and second table rotary axes
//   19709-19711 intersection offset vector from the tool axis (point D) to the tool rotary axis (point E)
//   19712-19714 intersection offset vector between the second and first tool rotary axes (E to F)
//   19666 tool holder offset (written 0: point D is the tool reference point of the machine description)
//    1220 external workpiece zero point offset (X Y Z): the workpiece datum at all rotary axes 0, so that the
//         datum follows the measured table axis line as the deviation set defines it
//
// Machine coordinates are those of the controlled point: a point on the first tool rotary axis (types 2, 21),
// or the tool reference point (types 0, 12); offsets in front of it move to the table side. Every value is absolute,
// in the controller's machine coordinate system at machine coordinates 0 (all axes at their Link::machineZero, rotary
// axes at 0 deg as A-79348E defines the vectors "when the rotation axes are all at 0 degrees").
// What the TCP parameters hold: the translation location errors (pivot positions, spindle offsets, axis
// offsets) and the constant part of the linear axes' positioning errors (a shift of all the axis carries). Orientation errors of rotary axes, squareness and component errors other than positioning have
// no 30i TCP parameter (3-D error compensation numbers are not public) and are reported NOT compensated.
#include <vector>

#include "controllers/common/controller_model.hpp"
#include "controllers/fanuc/parameter_file.hpp"

namespace cnccomp::controllers::fanuc {

struct RotaryParameter {
    int axis = -1;           ///< machine axis index; -1 hypothetical
    int direction = 3;       ///< 1 X, 2 Y, 3 Z
    int sense = 0;           ///< 0 right-hand about +direction, 1 left-hand
    double angleDeg = 0.0;   ///< hypothetical axis angle
};

struct TcpParameters {
    int type = 0;
    RotaryParameter rotary[2];
    int toolAxis = 3;
    Vec3 tablePosition = Vec3::Zero();      ///< 19700-19702
    Vec3 tableOffset = Vec3::Zero();        ///< 19703-19705
    Vec3 toolOffset = Vec3::Zero();         ///< 19709-19711 (D → E)
    Vec3 toolIntersection = Vec3::Zero();   ///< 19712-19714 (E → F)
    Vec3 workZero = Vec3::Zero();           ///< 1220 (X Y Z)
};

/// Parameters of the machine with the translation location errors of `values` (rotations ignored) and the linear axes'
/// positioning errors at the reference position (the constant part the pitch tables leave).
/// Throws ModelError for a structure the 30i TCP does not take (more than two rotary axes, two on one side
/// with type 21 impossible, linear axes on the table side, axes not along X/Y/Z, a tool not along an axis).
TcpParameters tcpFromMachine(const MachineModel& m, const Eigen::VectorXd& values);

/// Parameter lines (path 1; 1220 for the linear axes X Y Z).
std::vector<Parameter> tcpLines(const MachineModel& m, const TcpParameters& p);

/// Reads them back (InputError with the parameter's line).
TcpParameters tcpFromFile(const MachineModel& m, const ParameterFile& f);

/// The controller's kinematic chains described by the parameters (machine axes and travel from `m`), in machine
/// coordinates, as the 30i-A TCP manual defines them (A-79348E pp. 72-85): 19680 mechanical unit type (p.72),
/// 19682/19687 axis direction and 19684/19689 rotation direction "as a mechanical motion when a positive move command is
/// issued" (p.75), 19696 hypothetical axes (p.78), 19700-19705 rotary table position and the A -> B intersection offset
/// vector "in the machine coordinate system" with the rotation axes at 0 deg (p.82), 19709-19714 the D -> E and E -> F
/// vectors of the tool axes (16i-MB A-78712E pp. 61-62). No parameter holds the tool's roll about its axis or the
/// turn of the workpiece frame: those are taken from the description at machine coordinates 0.
void tcpChains(const MachineModel& m, const TcpParameters& p, std::vector<common::ChainElement>& workpiece,
               std::vector<common::ChainElement>& tool);

}  // namespace cnccomp::controllers::fanuc
