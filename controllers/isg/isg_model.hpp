#pragma once
// The ISG / Beckhoff TF5280 volumetric compensation as its documents describe it, rebuilt from the files alone (the
// apply model of the "isg" backend; it does not use the machine description's chains):
//
// - Chain (P-VOLC-00007 `chain`, TF5240 "Example of an AC machine with cardanic table"): the axis letters "in the
//   sequence along the path from the workpiece to the machine origin and from there to the tool tip" (example C, A, X,
//   Y, Z; TF5280 example machine XYZBC "CBYXZ"); the first `workpiece_axes` letters (P-VOLC-00008) are workpiece axes,
//   whose "orientation vector must be multiplied by -1".
// - Axes (TF5240 universal kinematics): X Y Z move along x y z, A B C turn about x y z, through their centre of
//   rotation PXA PYA PZA ... (TF5280 "List of parameters supported", mm; default the origin), all given at axis
//   values 0. Tool zero P0X P0Y P0Z (mm) and orientation N0X N0Y N0Z ("from the flange to the tool tip"); the active
//   tool length is applied along N0 (TF5280 "Tool length").
// - Errors (TF5280 "Parametric model to DIN ISO 230 and ISO/TR 16907"): position errors X0L Y0L Z0L A0L B0L C0L of axis
//   L (mm, rad) and component errors EXL ... ECL as tables over L's value (mm or deg; TF5280 "Units of measure").
//   [G] Where they act (no public document says): each axis moves as T(P)·E_pos·motion·E_comp·T(-P) in the machine
//   frame at axis values 0, P its centre of rotation (the origin for linear axes), E = translation then rotation by
//   the rotation vector (A, B, C); a workpiece axis carries the errors of the table's own motion and enters inverted.
//   Tables are interpolated linearly, end values held; a table over 0..360 deg wraps.
// - Compensation (TF5280 "Overview"): "only compensates for tool position ... not tool orientation": the corrected
//   axis values put the erroneous model's tool point where the error-free model has it, by moving X, Y and Z.
#include <map>
#include <string>
#include <vector>

#include "cnccomp/geometry.hpp"
#include "controllers/isg/isg_files.hpp"

namespace cnccomp::controllers::isg {

class IsgModel {
public:
    /// From the compensation list and the ISG_CSV blocks of its files. InputError (file:line) on names the model does
    /// not know, axes missing from the chain, tables that do not increase.
    IsgModel(const IsgConfig& config, const std::vector<std::pair<std::string, std::vector<IsgBlock>>>& files);

    /// Tool point at tool length `length` (mm along N0) for axis values `values` (letter → mm or deg), in the frame of
    /// the workpiece (the machine frame when the workpiece axes are at 0), with or without the errors.
    Vec3 toolPoint(const std::map<char, double>& values, double length, bool withErrors) const;

    const std::string& chain() const { return chain_; }

private:
    struct Table {
        std::vector<double> nodes;        ///< mm or deg, increasing
        std::vector<Vec6> values;         ///< mm, rad (x y z a b c)
        bool wraps = false;               ///< spans 0..360 deg
        Vec6 at(double position) const;
    };
    struct Axis {
        char letter = 'X';
        bool rotary = false;
        bool workpiece = false;
        Vec3 direction = Vec3::UnitX();
        Vec3 centre = Vec3::Zero();
        Vec6 position = Vec6::Zero();     ///< X0L ... C0L
        Table component;                  ///< EXL ... ECL over L (empty: none)
    };
    Pose motion(const Axis& a, double value, bool withErrors) const;

    std::string chain_;
    std::vector<Axis> axes_;  ///< in chain order
    int workpieceAxes_ = 0;
    Vec3 p0_ = Vec3::Zero(), n0_ = -Vec3::UnitZ();
};

}  // namespace cnccomp::controllers::isg
