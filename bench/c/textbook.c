/* Plain textbook C for the speed benchmark (bench/c_speed.py): R(p) for the parameterizations of
 * Table 1 and eq (35), written the way libraries usually write it, for comparison with the
 * generated headers. Not used by symrot itself.
 *
 * Algebraic parameterizations use their closed forms in x = |p|^2 (no branch needed). The others
 * go through the angle and axis, phi = phi(|p|), u = p/|p|, and Euler's formula
 * R = I + sin(phi) (u x) + (1 - cos(phi)) (u x)^2, switching to the first-order form
 * I + (p x) + (p x)^2/2 below the customary cutoff |p| < 1e-3.
 */
#include <math.h>
#include <stddef.h>

#define TEXTBOOK_CUTOFF 1e-3

/* R = I + a (p x) + b (p x)^2, row-major, with (p x)^2 = p p^T - x I. */
static inline void textbook_assemble(const double p[3], double x, double a, double b, double R[9]) {
    double d = 1.0 - b * x;
    R[0] = d + b * p[0] * p[0];
    R[1] = b * p[0] * p[1] - a * p[2];
    R[2] = b * p[0] * p[2] + a * p[1];
    R[3] = b * p[1] * p[0] + a * p[2];
    R[4] = d + b * p[1] * p[1];
    R[5] = b * p[1] * p[2] - a * p[0];
    R[6] = b * p[2] * p[0] - a * p[1];
    R[7] = b * p[2] * p[1] + a * p[0];
    R[8] = d + b * p[2] * p[2];
}

/* Euler's formula from the angle phi of a vector p of norm s (eq 1 with u = p/s). */
static inline void textbook_from_angle(const double p[3], double x, double s, double phi, double R[9]) {
    if (s < TEXTBOOK_CUTOFF) {
        textbook_assemble(p, x, 1.0, 0.5, R);
    } else {
        textbook_assemble(p, x, sin(phi) / s, (1.0 - cos(phi)) / x, R);
    }
}

/* eq (30): p = phi u */
void textbook_rotation_vector_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double s = sqrt(x);
    textbook_from_angle(p, x, s, s, R);
}

/* eq (31): p = sin(phi) u, cos(phi) = sqrt(1 - x) */
void textbook_linear_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    textbook_assemble(p, x, 1.0, 1.0 / (1.0 + sqrt(1.0 - x)), R);
}

/* eq (32): p = 2 sin(phi/2) u, cos(phi/2) = sqrt(1 - x/4) */
void textbook_euler_rodrigues_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    textbook_assemble(p, x, sqrt(1.0 - 0.25 * x), 0.5, R);
}

/* eq (33): p = 2 tan(phi/2) u */
void textbook_cayley_gibbs_rodrigues_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double k = 2.0 / (4.0 + x);
    textbook_assemble(p, x, 2.0 * k, k, R);
}

/* eq (34): p = 4 tan(phi/4) u */
void textbook_wiener_milenkovic_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double k = 1.0 / ((16.0 + x) * (16.0 + x));
    textbook_assemble(p, x, 16.0 * (16.0 - x) * k, 128.0 * k, R);
}

/* Table 1, sine family m = 4: p = 4 sin(phi/4) u, c = cos(phi/4) = sqrt(1 - x/16);
 * nu = c, nu^2/eps = c (2 c^2 - 1) (the paper's eq 38 prints eps = c^3/(2c^2 - 1): a typo). */
void textbook_sine_m4_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double c = sqrt(1.0 - x / 16.0);
    textbook_assemble(p, x, c * (2.0 * c * c - 1.0), 0.5 * c * c, R);
}

/* eq (35): p = cbrt(6 (phi - sin phi)) u; phi from |p| by Newton on 6 (phi - sin phi) = |p|^3. */
void textbook_det_h_one_rotation_matrix(const double p[3], double R[9]) {
    double x = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    double s = sqrt(x);
    double target = s * x, phi = s;
    int k;
    for (k = 0; k < 8; ++k) {
        double f = 6.0 * (phi - sin(phi)) - target;
        double df = 6.0 * (1.0 - cos(phi));
        if (df == 0.0) break;
        phi -= f / df;
    }
    textbook_from_angle(p, x, s, phi, R);
}
