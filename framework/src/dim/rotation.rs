//! The rotation algebra of 3D orientations: unit quaternions `q = (w, x, y, z)`
//! mapping body to world coordinates, rotation matrices and rotation vectors.

use super::d3::dot;

/// q / |q| (the identity for a zero quaternion).
pub fn normalize(q: [f64; 4]) -> [f64; 4] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if n > 0.0 {
        [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
    } else {
        [1.0, 0.0, 0.0, 0.0]
    }
}

/// The rotation matrix of a unit quaternion (rows).
pub fn rotation_matrix(q: [f64; 4]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q;
    [
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)],
    ]
}

/// R v.
pub fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let r = rotation_matrix(q);
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}

/// Rᵀ v.
pub fn rotate_inv(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    rotate([q[0], -q[1], -q[2], -q[3]], v)
}

/// The quaternion of a rotation vector (axis × angle, rad).
pub fn from_rotation_vector(r: [f64; 3]) -> [f64; 4] {
    let a = dot(r, r).sqrt();
    if a == 0.0 {
        return [1.0, 0.0, 0.0, 0.0];
    }
    let (s, c) = (0.5 * a).sin_cos();
    [c, s * r[0] / a, s * r[1] / a, s * r[2] / a]
}

/// The rotation vector of a unit quaternion.
pub fn to_rotation_vector(q: [f64; 4]) -> [f64; 3] {
    let q = if q[0] < 0.0 { [-q[0], -q[1], -q[2], -q[3]] } else { q };
    let s = (q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    if s == 0.0 {
        return [0.0; 3];
    }
    let a = 2.0 * s.atan2(q[0]);
    [a * q[1] / s, a * q[2] / s, a * q[3] / s]
}

/// a ⊗ b.
pub fn quat_mul(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn rotations() {
        let q = from_rotation_vector([0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let v = rotate(q, [1.0, 0.0, 0.0]);
        assert!((v[0]).abs() < 1e-15 && (v[1] - 1.0).abs() < 1e-15);
        let back = rotate_inv(q, v);
        assert!((back[0] - 1.0).abs() < 1e-15);
        let r = to_rotation_vector(q);
        assert!((r[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        let q2 = quat_mul(q, q);
        let v2 = rotate(q2, [1.0, 0.0, 0.0]);
        assert!((v2[0] + 1.0).abs() < 1e-15);
    }
}
