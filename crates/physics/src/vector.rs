//! Small fixed-size vector and matrix helpers (3-vectors, 3x3 row-major matrices, quaternions
//! `[x, y, z, w]` with the scalar last, as in the flight logs).

/// A 3-vector.
pub type Vec3 = [f64; 3];
/// A 3x3 matrix, row-major.
pub type Mat3 = [[f64; 3]; 3];

/// The unit vector along z (thrust direction in the body frame, "up" in the world frame).
pub const E3: Vec3 = [0.0, 0.0, 1.0];

pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(a: Vec3, s: f64) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

pub fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: Vec3) -> f64 {
    dot(a, a).sqrt()
}

/// Elementwise product.
pub fn hadamard(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] * b[0], a[1] * b[1], a[2] * b[2]]
}

pub fn mat_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `mᵀ v`.
pub fn mat_t_vec(m: &Mat3, v: Vec3) -> Vec3 {
    [
        m[0][0] * v[0] + m[1][0] * v[1] + m[2][0] * v[2],
        m[0][1] * v[0] + m[1][1] * v[1] + m[2][1] * v[2],
        m[0][2] * v[0] + m[1][2] * v[1] + m[2][2] * v[2],
    ]
}

pub fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    out
}

pub fn transpose(a: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = a[j][i];
        }
    }
    out
}

/// Column `j` of a matrix.
pub fn column(m: &Mat3, j: usize) -> Vec3 {
    [m[0][j], m[1][j], m[2][j]]
}

/// The skew-symmetric matrix of `v` (`hat(v) u = v × u`).
pub fn hat(v: Vec3) -> Mat3 {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}

/// The vector of the antisymmetric part of a matrix.
pub fn vee(s: &Mat3) -> Vec3 {
    [
        0.5 * (s[2][1] - s[1][2]),
        0.5 * (s[0][2] - s[2][0]),
        0.5 * (s[1][0] - s[0][1]),
    ]
}

/// Hamilton product of quaternions `[x, y, z, w]`.
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
pub fn quaternion_normalize(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if q[3] < 0.0 { -1.0 } else { 1.0 };
    q.map(|v| sign * v / n)
}

/// The quaternion of a rotation by the vector `theta` (axis times angle, rad).
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
pub fn rotation_from_rotation_vector(theta: Vec3) -> Mat3 {
    data::rotation_from_quaternion(&quaternion_from_rotation_vector(theta))
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
        let product = data::rotation_from_quaternion(&quaternion_multiply(qa, qb));
        let composed = mat_mul(
            &data::rotation_from_quaternion(&qa),
            &data::rotation_from_quaternion(&qb),
        );
        for i in 0..3 {
            for j in 0..3 {
                assert!((product[i][j] - composed[i][j]).abs() < 1e-12);
            }
        }
    }
}
