#pragma once
// The machine model: two serial chains from the bed (workpiece side, tool side), each link one axis
// (linear, rotary or fixed) plus a fixed placement, and the named deviation parameters the machine admits.
// Immutable once built; algorithms take it by const reference (Model/Data split as in Pinocchio).
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "cnccomp/geometry.hpp"

namespace cnccomp {

inline constexpr int kMaxAxes = 9;
/// Commanded positions of the controlled axes, in the machine's axis order (mm for linear, rad for rotary).
/// Fixed capacity so that hot loops never allocate.
using AxisVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxAxes, 1>;

enum class AxisKind { Linear, Rotary, Fixed };
enum class Side { Workpiece, Tool };

/// One link of a chain: frame_i = frame_{i-1} · placement · E_location · motion(q) · E_component(q).
struct Link {
    std::string name;                  ///< axis letter (X, Y, Z, A, B, C) or a fixed link's name (e.g. C1, the tool spindle)
    AxisKind kind = AxisKind::Fixed;
    Vec3 direction = Vec3::UnitZ();    ///< unit direction of motion / rotation, in the placed frame
    Pose placement = Pose::Identity(); ///< nominal fixed transform from the previous frame
    double min = -std::numeric_limits<double>::infinity();  ///< travel, mm or rad
    double max = std::numeric_limits<double>::infinity();
    bool modulo = false;               ///< rotary axis that wraps at 360°
    int axisIndex = -1;                ///< index into AxisVector; -1 for fixed links
    /// Where the controller's machine zero is on this axis: the command (mm or rad, in this description's frame) at
    /// which the controller's machine coordinate of the axis reads 0. Controller position = command − machineZero.
    /// Default 0: the commands of the description are the controller's machine coordinates.
    double machineZero = 0.0;
};

struct Chain {
    Side side = Side::Tool;
    std::vector<Link> links;
};

enum class DeviationKind { Location, Component };

/// Parametrisation of a position-dependent (component) error e(q) of one link's own axis.
struct ComponentBasis {
    enum class Type { Polynomial, Fourier, Table };
    Type type = Type::Polynomial;
    int order = 1;              ///< polynomial degree (terms q^1..q^order) or Fourier harmonics (cos, sin pairs)
    std::vector<double> nodes;  ///< table nodes in axis units (mm or rad), strictly increasing
    /// Number of coefficients in the flat vector.
    int size() const;
    /// e(q) = Σ coef_k · basis_k(q); `coef` points at size() values.
    double evaluate(double q, const double* coef, bool moduloAxis) const;
};

/// One term of a linear relation between deviations: coefficient × (a value of deviation `deviation`).
struct DeviationTerm {
    int deviation = -1;
    double coefficient = 0;
};

/// One named deviation parameter: which link's error transform it enters, and which of its six
/// components (0..5 = x y z a b c). Location errors are constants placed before the link's motion;
/// component errors are functions of the link's own axis position placed after it.
///
/// Three values belong to one deviation (see iso_names.hpp): the *link value* (the error component itself, what the
/// flat deviation vector holds and the kinematics use), the value under the ISO 230-1 `name` (the quantity the
/// standard defines, with its reference axis and sign: a linear combination of link values) and the value under the
/// paper `alias` (aliasSign × link value).
struct DeviationDef {
    std::string name;         ///< ISO 230-1 style, e.g. EX0C, EA0Z, EXC
    std::string alias;        ///< paper symbol in ASCII (δ→d, α→a, β→b, γ→g), may be empty
    double aliasSign = 1.0;   ///< value under the alias = aliasSign × link value (the paper's own sign)
    /// Value under the ISO name = Σ coefficient · link value of `deviation` (location errors; filled by finalize()).
    std::vector<DeviationTerm> isoTerms;
    /// Inverse: link value = Σ coefficient · ISO value of `deviation` (filled by finalize()).
    std::vector<DeviationTerm> linkTerms;
    std::string description;
    Side side = Side::Tool;
    int link = 0;             ///< index into the chain's links
    int component = 0;        ///< 0..2 translation x,y,z; 3..5 rotation a,b,c
    DeviationKind kind = DeviationKind::Location;
    ComponentBasis basis;     ///< only for Component
    int offset = 0;           ///< first index in the flat deviation vector
    int size() const { return kind == DeviationKind::Location ? 1 : basis.size(); }
    bool isAngle() const { return component >= 3; }
};

class MachineModel {
public:
    std::string name;
    std::string description;
    std::string sourceFile;
    Chain workpiece{Side::Workpiece, {}};
    Chain tool{Side::Tool, {}};
    Vec3 toolDirection = -Vec3::UnitZ();  ///< spindle → tip, in the last tool-chain frame
    std::vector<std::string> axisNames;   ///< controlled axes; index = position in AxisVector
    std::vector<DeviationDef> deviations;

    const Chain& chain(Side s) const { return s == Side::Tool ? tool : workpiece; }
    int axisCount() const { return static_cast<int>(axisNames.size()); }
    /// Index of a controlled axis by name, or -1.
    int axisIndex(std::string_view axis) const;
    /// Index of a controlled axis by name; throws ModelError naming the machine.
    int requireAxis(std::string_view axis) const;
    /// The link of a controlled axis.
    const Link& axisLink(int axisIndex) const;
    /// Which chain an axis belongs to.
    Side axisSide(int axisIndex) const;
    /// Nominal direction of an axis in the bed frame, with the axes before it at zero.
    Vec3 nominalDirection(int axisIndex) const;
    /// Deviation index by ISO name or alias (case-sensitive), or -1.
    int deviationIndex(std::string_view nameOrAlias) const;
    /// Total length of the flat deviation vector.
    int parameterCount() const;
    /// The controller's machine coordinates of commands q (command − machineZero, per axis; mm and rad).
    AxisVector toController(const AxisVector& q) const;
    /// Commands of this description from the controller's machine coordinates p (p + machineZero).
    AxisVector fromController(const AxisVector& p) const;
    /// True when some axis has a non-zero machineZero.
    bool hasMachineZero() const;
    /// Fill axisNames/axisIndex/offsets, derive the ISO meaning of the deviation names (iso_names.hpp) and check
    /// consistency; throws ModelError.
    void finalize();
};

}  // namespace cnccomp
