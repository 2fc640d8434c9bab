// Numbers as the tables and messages print them.
#pragma once

#include <string>

namespace beamrail {

// Shortest text that reads back as exactly x ("nan", "inf", "-inf" for non-finite values).
std::string format_number(double x);

}  // namespace beamrail
