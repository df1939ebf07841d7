#pragma once
// Machines for the laser tests (test_laser_deviation.cpp, test_laser_controllers.cpp): the sample mills with their
// positioning component EXX as a table at the targets of samples/laser/mill-3axis-x.csv.
#include <string>

#include <fmt/format.h>

namespace cnccomp::test {

// The targets of samples/laser/mill-3axis-x.csv as table nodes of EXX.
inline const char* kNodes = "-400 -321.7 -238.4 -160.9 -79.3 0 81.6 158.2 242.7 319.5 400";

/// The sample gantry mill (X Y Z on the tool side) with EXX as a table at the laser's targets.
inline std::string gantryXml() {
    return fmt::format(R"(<machine name="gantry-laser">
  <workpiece><fixed name="T"/></workpiece>
  <tool direction="0 0 -1">
    <axis name="X" type="linear" direction="1 0 0" min="-400" max="400"/>
    <axis name="Y" type="linear" direction="0 1 0" min="-250" max="250"/>
    <axis name="Z" type="linear" direction="0 0 1" min="-450" max="0"/>
    <fixed name="S"/>
  </tool>
  <deviations>
    <location name="EC0Y" link="Y" component="c"/>
    <component name="EXX" link="X" component="x" basis="table" nodes="{}"/>
  </deviations>
</machine>
)", kNodes);
}

/// The knee mill of samples/machines/mill-3axis-table-xy.xml (table X on saddle Y, moving opposite to the command)
/// with EXX as a table: the component moves the workpiece, so it reads with the opposite sign.
inline std::string kneeXml() {
    return fmt::format(R"(<machine name="knee-laser">
  <workpiece>
    <axis name="Y" type="linear" direction="0 -1 0" min="-250" max="250"/>
    <axis name="X" type="linear" direction="-1 0 0" min="-400" max="400"/>
  </workpiece>
  <tool direction="0 0 -1">
    <axis name="Z" type="linear" direction="0 0 1" min="-450" max="0"/>
    <fixed name="S"/>
  </tool>
  <deviations>
    <location name="EC0X" link="X" component="c"/>
    <component name="EXX" link="X" component="x" basis="table" nodes="{}"/>
  </deviations>
</machine>
)", kNodes);
}

}  // namespace cnccomp::test
