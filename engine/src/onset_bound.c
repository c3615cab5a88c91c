// polydyn — the error bound of a corrected onset (onset_bound.h, design note there).
#include "onset_bound.h"

#include <math.h>

double pd_onset_error_bound(double omega, double tau, double depth, double approach, double vmax, double size,
                            double friction, double spring) {
  double wt = omega * tau;
  double velocity = (PD_ONSET_BOUND_C * wt * wt * wt * fabs(approach) + friction) / vmax;
  double position = fmax(depth, 0.0) * wt * wt / (6.0 * size);
  return fmax(fmax(velocity, position), spring);
}

double pd_transition_error_bound(double kink, double h) { return kink * h * h / 96.0; }

