#pragma once
// The share of a box where a function is proven positive from its value at the centre and
// an enclosure of its gradient over the box (mean-value form). The certified volumes use it
// for the cells a surface crosses: a whole-cell proof fails there, a share of the cell
// does not (docs/kinematics.md, "Certified volumes").

#include <Eigen/Core>

#include "maximal_workspace/model/interval.h"

namespace maximal_workspace {

// A lower bound of the share of the box centre +/- half_width (axes with zero half width
// left out) where f > 0, for f with f(centre) >= value and grad f in `gradient` over the
// box: below f lies a plane (mean-value form), and the share of a box above a plane has a
// closed form.
double provenPositiveShare(double value, const IntervalPoint& gradient, const Eigen::Vector3d& half_width);

}  // namespace maximal_workspace
