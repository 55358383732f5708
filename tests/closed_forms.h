#pragma once
// Textbook form factors the tests compare against (Howell's catalogue of configuration
// factors), in one place.
#include <cmath>

#include "util/math.h"

namespace radiosa::test {

// A plane element on the axis of a 2a x 2b rectangle at distance h, facing it (Howell B-3).
inline double element_on_rectangle_axis(double a, double b, double h) {
    const double A = a / h, B = b / h;
    return 2.0 / kPi *
           (A / std::sqrt(1 + A * A) * std::atan(B / std::sqrt(1 + A * A)) +
            B / std::sqrt(1 + B * B) * std::atan(A / std::sqrt(1 + B * B)));
}

}  // namespace radiosa::test
