#pragma once
// A LinuxCNC 2.9 kinematics component generated from the machine model: the exact model of the machine with its
// identified deviations (every location, squareness and component error; exact rotations), forward and inverse, for
// any structure a machine XML describes (two serial chains from the bed, src/cnccomp/kinematics.hpp), as the source
// of a halcompile `.comp` file.
//
// Interface followed (LinuxCNC 2.9, tag v2.9.0): src/hal/components/userkins.comp (a kinematics component is a
// realtime halcompile component whose C section defines kinematicsForward/kinematicsInverse/kinematicsType and whose
// HAL pins are made in a setup function called from the first kinematicsType() call, because the kinematics
// functions are called by motion, not by a thread),
// src/hal/components/millturn.comp (switchable kinematics in a .comp: kinematicsSwitchable() = 1,
// kinematicsSwitch(type), pins kinstype.is-N), src/emc/kinematics/kinematics.h (the prototypes, KINEMATICS_BOTH),
// src/emc/motion/control.c (kinematicsInverse gets the joints array preloaded with the joints' current coarse
// positions: the warm start), src/emc/kinematics/trtfuncs.c (tool-offset pin fed from motion.tooloffset.z).
#include <string>

#include "cnccomp/deviations.hpp"
#include "cnccomp/inverse_kinematics.hpp"
#include "cnccomp/machine.hpp"

namespace cnccomp::controllers::linuxcnc {

/// How the component is generated. Defaults fit a 1 ms servo thread (see README, LinuxCNC kinematics component).
struct KinsComponentOptions {
    /// halcompile component name: the file must be `<name>.comp`, the INI says `[KINS] KINEMATICS=<name>`, and every
    /// HAL pin is `<name>.<pin>`. Lower-case letters, digits and '_', starting with a letter (halcompile takes the
    /// component name as a C identifier). Throws ModelError otherwise.
    std::string name = "cnccomp_kins";
    /// Newton iterations per inverse (and per forward) call at most.
    int maxIterations = 12;
    /// Convergence: step size below this (mm, and rad × axisWeight) ends the iteration.
    double tolerance = 1e-11;
    /// mm per rad: weight of a tool-axis error against a tip error (as cnccomp::IkOptions::axisWeight).
    double axisWeight = 100.0;
    /// mm per rad: λ of the singular-pose policy (cnccomp::SingularPosePolicy, src/cnccomp/pose_solver.hpp; as
    /// cnccomp::IkOptions::rotaryRegularization): the damping D = λ² Σ φ(σᵢ) vᵢ vᵢᵀ pulls the rotary joints towards
    /// the nominal (joint mode) or commanded (tool-tip mode) angles in the directions that cannot turn the tool axis,
    /// only near a singular pose (singularZone): damped least squares with variable damping [NakamuraHanafusa1986],
    /// [Chiaverini1994] in the ill-conditioned directions only [MaciejewskiKlein1988]. Chosen as
    /// axisWeight · singularZone, so the pull and the axis weigh alike where the damping fades out. Extra linear
    /// joints (not X Y Z, on a machine with linear X Y Z) keep a constant pull of this weight in the component
    /// (solveToolPose has none; no sample machine has such a joint).
    double rotaryRegularization = 10.0;
    /// cnccomp::IkOptions::singularZone: σ0 of the policy, the sine of the angle between the tool axis and a rotary
    /// axis below which the damping acts in that direction, weighted φ(σ) = (1 − σ/σ0)² ([G], cnccomp's shape; σᵢ the
    /// singular values of the tool axis' derivative over the rotary joints). Outside it the axis is met exactly
    /// (nothing damped); inside, a tool-axis error δ turns the rotary axes by at most about 1.21·δ/0.1 = 12·δ (0.017°
    /// for 5″), smoothly across the singular pose, and the tip at the tool-offset length is exact everywhere (the
    /// slides can always place it). With a constant pull of 0.1 mm/rad the real LinuxCNC swung C by ±1.8° within a
    /// few servo cycles at B = ±180° on the multi-tasking sample (3 mm of Y, 1.5 µm off the path after motion's joint
    /// interpolation).
    double singularZone = 0.1;
    /// cnccomp::IkOptions::polish. Off: the joints are a smooth function of the world words, which the trajectory
    /// needs (a polish switched on and off near a singular pose makes the joints jump).
    bool polish = false;
};

/// Source text of a halcompile `.comp` kinematics component for machine `m` with deviations `d` (LinuxCNC 2.9).
///
/// Joints and coordinates: one joint per controlled axis, joint i = machine axis i (m.axisNames order), value = the
/// controller's machine coordinate of that axis (command − machineZero; mm, degrees). The coordinate letter of joint i
/// is m.axisNames[i] (each must be one of X Y Z A B C U V W, all different; else ModelError). The INI needs
///   [KINS] KINEMATICS=<name>   JOINTS=<axisCount>
///   [TRAJ] COORDINATES=<the axis letters in joint order>   (e.g. "CZYXB" for the multi-tasking sample)
///
/// Modes (switchable, as millturn.comp / switchkins: motion.switchkins-type or M-codes calling kinematicsSwitch):
///   type 0, joint mode (default at start): the world coordinates are the NOMINAL machine's commands, in controller
///     coordinates; inverse = joints at which the ERRONEOUS machine puts the tool tip and the tool axis where the
///     nominal machine at those commands puts them (tip exact, axis in the least-squares sense where the axes cannot
///     match it); forward = nominal commands whose nominal pose is the erroneous pose at the joints.
///   type 1, tool-tip mode: X Y Z = tool tip in workpiece coordinates (the workpiece frame of the machine model at
///     machine zero = all commands 0), rotary words = the rotary axes' nominal angles (controller coordinates);
///     inverse = joints of the erroneous machine putting its tip there with the nominal tool axis of those angles.
///   The tool length in both modes is the pin `<name>.tool-offset` (mm, along the tool direction from the tool
///   frame's origin; the HAL file should `net` it from motion.tooloffset.z, as for xyzac-trt-kins).
///
/// HAL pins (all made by the component; `<name>.` prefix):
///   in  float tool-offset                   tool length, mm
///   in  float dev.<iso-name>                one per location deviation: its LINK value (the error component the
///                                           kinematic chain uses, DeviationDef; mm or rad); initial value = d's value
///   in  float dev.<iso-name>.<k>            component deviations: coefficient k (0-based) of the basis (polynomial
///                                           q^(k+1), Fourier cos/sin pairs, table node k), q in mm or rad; mm or rad
///                                           (<iso-name> lower-cased, e.g. dev.ex0c, dev.ecc.3)
///   out bit   kinstype.is-0 / kinstype.is-1 which mode is active (names as millturn.comp: no prefix)
///   out bit   fail                          set when the last inverse/forward did not converge; an inverse whose
///                                           tip residual is still above 1e-6 mm (or not finite) leaves the joints
///                                           as LinuxCNC passed them and returns -1 (motion then stops with
///                                           "kinematicsInverse failed"): no NaN reaches the joints
///   out s32   iterations                    Newton iterations of the last inverse call
///   out float residual                      mm: tip residual of the last inverse call
/// The compiled-in initial values equal d, so a HAL file that sets nothing gives the identified model; setting the
/// dev.* pins (setp) changes the model at run time (read back with getp).
///
/// Build: `halcompile --install <name>.comp` (Debian package linuxcnc-uspace-dev; sudo for a package install).
/// halcompile needs one instance pin: `<name>.0.generated` (out s32, always 1); the kinematics pins above are made by
/// the component's setup, called from motion's first kinematicsType() call (userkins.comp, note 2).
/// kinematicsType() = KINEMATICS_BOTH; kinematicsSwitchable() = 1.
/// Throws ModelError for a machine the component cannot describe (axis names, more than 9 axes).
std::string kinematicsComponent(const MachineModel& m, const DeviationSet& d, const KinsComponentOptions& o = {});

/// cnccomp's inverse (solveToolPose) with the component's objective: its weights, singular-pose policy and polish, and
/// a tolerance at least as tight as the component's. The apply model (component_route.hpp) and the tests solve with
/// these.
IkOptions kinsSolverOptions(const KinsComponentOptions& o = {});

/// HAL pin name (without the component prefix) of coefficient k of deviation `index` of `m`: "dev.<lower iso name>"
/// for a location deviation, "dev.<lower iso name>.<k>" for a component deviation.
std::string kinsDeviationPin(const MachineModel& m, int index, int k = 0);

}  // namespace cnccomp::controllers::linuxcnc
