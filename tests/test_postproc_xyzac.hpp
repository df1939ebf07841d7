#pragma once
// The machine of LinuxCNC's switchable xyzac-trt sim (configs/sim/axis/vismach/5axis/table-rotary-tilting/xyzac-trt.ini:
// y-offset 20, z-offset 10, rot-points 0, conventional-directions 0), with the location errors the TCP tests and the
// benchmark use: A tilts the table about X through y = 20, z = 10; C turns on it through the machine origin.
namespace cnccomp::test {

inline constexpr const char* kXyzacTrtMachine = R"xml(<?xml version="1.0" encoding="UTF-8"?>
<machine name="linuxcnc-xyzac-trt" description="LinuxCNC sim xyzac-trt-kins: A tilts the table about X through y=20 z=10, C turns on it through the machine origin">
  <workpiece>
    <axis name="A" type="rotary" direction="1 0 0" min="-100" max="50" offset="0 20 10"/>
    <axis name="C" type="rotary" direction="0 0 1" min="-36000" max="36000" offset="0 -20 -10"/>
  </workpiece>
  <tool direction="0 0 -1">
    <axis name="X" type="linear" direction="1 0 0" min="-200" max="200"/>
    <axis name="Y" type="linear" direction="0 1 0" min="-100" max="100"/>
    <axis name="Z" type="linear" direction="0 0 1" min="-120" max="120"/>
  </tool>
  <deviations>
    <location name="EY0A" link="A" component="y"/>
    <location name="EZ0A" link="A" component="z"/>
    <location name="EA0A" link="A" component="a"/>
    <location name="EB0A" link="A" component="b"/>
    <location name="EC0A" link="A" component="c"/>
    <location name="EX0C" link="C" component="x"/>
    <location name="EY0C" link="C" component="y"/>
    <location name="EA0C" link="C" component="a"/>
    <location name="EB0C" link="C" component="b"/>
    <location name="EC0Y" link="Y" component="c"/>
  </deviations>
</machine>
)xml";

}  // namespace cnccomp::test
