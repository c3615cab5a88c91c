// polydyn — out-of-line vector helpers.
#include "polydyn/vecmath.h"

pdQuat pd_quat_from_mat3(const pdMat3* r) {
  const double(*m)[3] = r->m;
  double trace = m[0][0] + m[1][1] + m[2][2];
  pdQuat q;
  // Shepperd: divide by the largest of the four candidate components for accuracy
  if (trace >= m[0][0] && trace >= m[1][1] && trace >= m[2][2]) {
    double s = 2.0 * sqrt(1.0 + trace);
    q = (pdQuat){0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s};
  } else if (m[0][0] >= m[1][1] && m[0][0] >= m[2][2]) {
    double s = 2.0 * sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]);
    q = (pdQuat){(m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s};
  } else if (m[1][1] >= m[2][2]) {
    double s = 2.0 * sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]);
    q = (pdQuat){(m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s};
  } else {
    double s = 2.0 * sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]);
    q = (pdQuat){(m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s};
  }
  if (q.w < 0.0) q = (pdQuat){-q.w, -q.x, -q.y, -q.z};
  return pd_quat_normalize(q);
}
