#pragma once
// The virtual calibration sphere of the LinuxCNC probing tests: the HAL component tests/linuxcnc/virtual_sphere.comp
// (the erroneous A/C table-table machine, the truth, written from the ISO 230-1 definitions apart from cnccomp's model;
// see its description), installed under a module name of its own, wired into a sim configuration by a HAL text, and
// the reader of the probing programs' LOG lines.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "cnccomp/geometry.hpp"

namespace cnccomp::test::virtual_sphere {

/// The truth: location errors of the A and C axes under their ISO 230-1 names (EY0A EZ0A EX0C EY0C in mm, EB0A EC0A
/// EA0C EB0C in rad). Names the component does not have are refused by parameterHal.
using Truth = std::map<std::string, double>;

struct Setup {
    double toolLength = 0;     ///< spindle reference point to the ball centre along −Z, mm
    double ballRadius = 3;     ///< stylus ball, mm
    double sphereRadius = 12.7;
    Vec3 sphere = Vec3::Zero();  ///< sphere centre in the table frame, mm
    double triggerTravel = 0;  ///< the probe's pre-travel, mm
    Truth truth;
};

/// halcompile's source of the component (tests/linuxcnc/virtual_sphere.comp), component name "virtual_sphere".
std::filesystem::path source();

/// `setp` lines for every parameter of the setup (%.17g).
std::string parameterHal(const std::string& module, const Setup& s);
/// The HAL file of the harness: load the module, add its function to the servo thread after motion, feed it the
/// joint.N.motor-pos-cmd signals of base.hal (signals j<n>; `coordinates` = the joint letters in joint order, which
/// must hold X Y Z A C), net its probe to motion.probe-input, then parameterHal.
std::string hal(const std::string& module, const std::string& coordinates, const Setup& s);
/// The truth as a cnccomp deviation CSV (µm and arcsec, ISO names).
std::string truthCsv(const Truth& t);

/// One line `TOUCH <pose> <touch> <#5070> <#5061> ... <#5066>` of a probing program's log (LOGOPEN/LOG).
struct Touch {
    int pose = 0, touch = 0;
    bool ok = false;           ///< #5070: the probe tripped
    double x = 0, y = 0, z = 0, a = 0, b = 0, c = 0;  ///< #5061..#5066, program coordinates (mm, deg)
};
/// Reads every TOUCH line of a log; throws std::runtime_error naming the line when one is malformed.
std::vector<Touch> readTouches(const std::filesystem::path& log);
/// For linuxcnc_sim::run's `suspect`: why the run looks hit by LinuxCNC's probing race (a log missing, or a touch logged
/// with #5070 = 0 although every probing move of these programs ends inside the sphere), or empty.
std::string raceSuspect(const std::vector<std::filesystem::path>& logs);

}  // namespace cnccomp::test::virtual_sphere
