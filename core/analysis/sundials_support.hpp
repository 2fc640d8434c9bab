// Small owners for SUNDIALS objects, so that every exit path frees them, and an error handler that
// keeps SUNDIALS' last message instead of printing it.
#pragma once

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <string>

namespace beamrail {

class SundialsContext {
 public:
  SundialsContext() { SUNContext_Create(nullptr, &ctx_); }
  ~SundialsContext() { SUNContext_Free(&ctx_); }
  SundialsContext(const SundialsContext&) = delete;
  SundialsContext& operator=(const SundialsContext&) = delete;
  operator SUNContext() const { return ctx_; }

 private:
  SUNContext ctx_ = nullptr;
};

class SerialVector {
 public:
  SerialVector(long n, SUNContext ctx) : v_(N_VNew_Serial(n, ctx)) {}
  ~SerialVector() {
    if (v_) N_VDestroy(v_);
  }
  SerialVector(const SerialVector&) = delete;
  SerialVector& operator=(const SerialVector&) = delete;
  operator N_Vector() const { return v_; }
  double* data() const { return N_VGetArrayPointer(v_); }

 private:
  N_Vector v_;
};

struct MatrixOwner {
  SUNMatrix m = nullptr;
  ~MatrixOwner() {
    if (m) SUNMatDestroy(m);
  }
};

struct LinearSolverOwner {
  SUNLinearSolver s = nullptr;
  ~LinearSolverOwner() {
    if (s) SUNLinSolFree(s);
  }
};

// Collects the last error SUNDIALS reported (install with CVodeSetErrHandlerFn and friends).
struct SundialsMessages {
  std::string last;
  static void handler(int code, const char* module, const char* function, char* msg, void* self) {
    auto* m = static_cast<SundialsMessages*>(self);
    m->last = std::string(module ? module : "") + " " + (function ? function : "") + " (" +
              std::to_string(code) + "): " + (msg ? msg : "");
  }
};

}  // namespace beamrail
