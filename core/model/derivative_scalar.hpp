// What Eigen needs to know of the scalars that carry derivatives (Dual, HyperDual, Jet3): real,
// signed, initialized before use, with their costs; each type's NumTraits derives from this.
#pragma once

#include <Eigen/Core>

namespace beamrail {

template <class T, int add_cost, int mul_cost>
struct DerivativeScalarTraits : Eigen::NumTraits<double> {
  using Real = T;
  using NonInteger = T;
  using Nested = T;
  using Literal = T;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = add_cost,
    MulCost = mul_cost
  };
};

}  // namespace beamrail
