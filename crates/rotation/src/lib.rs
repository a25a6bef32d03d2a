//! 3-vectors, 3×3 matrices (row-major) and quaternions `[x, y, z, w]` (scalar last, as in the
//! flight logs): the one home of the attitude maths that the flight-log reader (`data`: a log's
//! rotation matrices from its quaternions, the frame of its rates), the simulator and the residual
//! force (`physics`, re-exported as `physics::vector`) and the mismatch analysis share.
//!
//! What it is for: plain arithmetic on fixed-size arrays, each function written once, so that every
//! crate computes a rotation with the same operations in the same order (the simulated logs and the
//! analyses are compared byte for byte). What it is not for: anything with a dependency, a unit
//! check or a frame convention beyond body-to-world rotations; general linear algebra is `faer`'s.
//! The small functions are `#[inline]`, as they were when they lived beside their callers.

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A 3x3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// The unit vector along z (thrust direction in the body frame, "up" in the world frame).
pub const E3: Vec3 = [0.0, 0.0, 1.0];

#[inline]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

#[inline]
pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// Elementwise product.
#[inline]
pub fn hadamard(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

#[inline]
pub fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `mᵀ v`.
#[inline]
pub fn mat_t_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

#[inline]
pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

#[inline]
pub fn transpose(a: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = a[j][i];
        }
    }
    out
}

/// `a − b`, entry by entry.
#[inline]
pub fn mat_sub(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = *a;
    for (row, other) in out.iter_mut().zip(b) {
        for (cell, value) in row.iter_mut().zip(other) {
            *cell -= value;
        }
    }
    out
}

/// `s a`, entry by entry.
#[inline]
pub fn mat_scale(a: &Mat3, s: f64) -> Mat3 {
    a.map(|row| row.map(|v| v * s))
}

/// Column `j` of a matrix.
#[inline]
pub fn column(m: &Mat3, j: usize) -> Vec3 {
    [m[0][j], m[1][j], m[2][j]]
}

/// The skew-symmetric matrix of `v` (`hat(v) u = v × u`).
#[inline]
pub fn hat(v: Vec3) -> Mat3 {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}

/// The vector of the antisymmetric part of a matrix.
#[inline]
pub fn vee(s: &Mat3) -> Vec3 {
    [
        0.5 * (s[2][1] - s[1][2]),
        0.5 * (s[0][2] - s[2][0]),
        0.5 * (s[1][0] - s[0][1]),
    ]
}

/// Hamilton product of quaternions `[x, y, z, w]`.
#[inline]
pub fn quaternion_multiply(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// The quaternion scaled to unit norm, with a non-negative scalar part.
#[inline]
pub fn quaternion_normalize(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
    q.map(|v| sign * v / n)
}

/// The quaternion of a rotation by the vector `theta` (axis times angle, rad).
#[inline]
pub fn quaternion_from_rotation_vector(theta: Vec3) -> [f64; 4] {
    let angle = norm(theta);
    if angle < 1e-12 {
        return quaternion_normalize([theta[0] / 2.0, theta[1] / 2.0, theta[2] / 2.0, 1.0]);
    }
    let s = (angle / 2.0).sin() / angle;
    [
        theta[0] * s,
        theta[1] * s,
        theta[2] * s,
        (angle / 2.0).cos(),
    ]
}

/// The rotation matrix of a rotation vector (Rodrigues).
#[inline]
pub fn rotation_from_rotation_vector(theta: Vec3) -> Mat3 {
    rotation_from_quaternion(&quaternion_from_rotation_vector(theta))
}

/// Rotation matrix (body to world) of a unit quaternion `[x, y, z, w]`.
#[inline]
pub fn rotation_from_quaternion(q: &[f64; 4]) -> Mat3 {
    let [x, y, z, w] = *q;
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// Unit quaternion `[x, y, z, w]` (w ≥ 0) of a rotation matrix.
#[inline]
pub fn quaternion_from_rotation(r: &Mat3) -> [f64; 4] {
    let trace = r[0][0] + r[1][1] + r[2][2];
    let q = if trace > 0.0 {
        let s = (trace + 1.0).sqrt() * 2.0;
        [
            (r[2][1] - r[1][2]) / s,
            (r[0][2] - r[2][0]) / s,
            (r[1][0] - r[0][1]) / s,
            0.25 * s,
        ]
    } else if r[0][0] > r[1][1] && r[0][0] > r[2][2] {
        let s = (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt() * 2.0;
        [
            0.25 * s,
            (r[0][1] + r[1][0]) / s,
            (r[0][2] + r[2][0]) / s,
            (r[2][1] - r[1][2]) / s,
        ]
    } else if r[1][1] > r[2][2] {
        let s = (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt() * 2.0;
        [
            (r[0][1] + r[1][0]) / s,
            0.25 * s,
            (r[1][2] + r[2][1]) / s,
            (r[0][2] - r[2][0]) / s,
        ]
    } else {
        let s = (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt() * 2.0;
        [
            (r[0][2] + r[2][0]) / s,
            (r[1][2] + r[2][1]) / s,
            0.25 * s,
            (r[1][0] - r[0][1]) / s,
        ]
    };
    if q[3] < 0.0 { q.map(|v| -v) } else { q }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hat_is_the_cross_product_and_vee_inverts_it() {
        let a = [0.3, -1.2, 2.0];
        let b = [1.5, 0.4, -0.7];
        let via_hat = mat_vec(&hat(a), b);
        let direct = cross(a, b);
        for i in 0..3 {
            assert!((via_hat[i] - direct[i]).abs() < 1e-15);
        }
        assert_eq!(vee(&hat(a)), a);
    }

    #[test]
    fn quaternion_product_composes_rotations() {
        let qa = quaternion_from_rotation_vector([0.2, -0.1, 0.4]);
        let qb = quaternion_from_rotation_vector([-0.3, 0.5, 0.1]);
        let product = rotation_from_quaternion(&quaternion_multiply(qa, qb));
        let composed = mat_mul(
            &rotation_from_quaternion(&qa),
            &rotation_from_quaternion(&qb),
        );
        for i in 0..3 {
            for j in 0..3 {
                assert!((product[i][j] - composed[i][j]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn quaternion_and_rotation_round_trip() {
        let q = {
            let raw = [0.1, -0.3, 0.2, 0.9];
            let n = raw.iter().map(|v: &f64| v * v).sum::<f64>().sqrt();
            raw.map(|v| v / n)
        };
        let r = rotation_from_quaternion(&q);
        let back = quaternion_from_rotation(&r);
        for i in 0..4 {
            assert!((q[i] - back[i]).abs() < 1e-12);
        }
        let rrt = mat_mul(&r, &transpose(&r));
        for (i, row) in rrt.iter().enumerate() {
            for (j, value) in row.iter().enumerate() {
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((value - expected).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn difference_and_scale_are_entry_by_entry() {
        let a = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]];
        let b = transpose(&a);
        let d = mat_scale(&mat_sub(&a, &b), 0.5);
        assert_eq!(d, [[0.0, -1.0, -2.0], [1.0, 0.0, -1.0], [2.0, 1.0, 0.0]]);
        assert_eq!(vee(&d), [1.0, -2.0, 1.0]);
    }
}
