//! A linear-elastic static finite-element solution on the solver's own tets, in f64: the
//! reference the validation tests compare a settled XPBD body with (same mesh, same
//! lumped loads, same Lamé pair), so that mesh locking and discretisation cancel and what
//! is left is the solver's own error.
//!
//! Linear tets (constant strain): `ε = sym(Σ_a u_a ⊗ ∇_a)`, `σ = 2μ ε + λ tr(ε) I`, nodal
//! force `f_a = V σ ∇_a` with `∇_1..3` the columns of `Dm⁻ᵀ` and `∇_0 = −Σ ∇_1..3`
//! (PHYSICS.md §1.1's shape matrix). `K u = f` is solved by Jacobi-preconditioned
//! conjugate gradients, matrix-free, with the pinned nodes' rows and columns removed.

use glam::DVec3;
use incise_sim::TetMesh;
use incise_sim::material::Lame;

/// Shape-function gradients of every tet, `[∇_0, ∇_1, ∇_2, ∇_3]`, and its rest volume.
struct Elements {
    grads: Vec<[DVec3; 4]>,
    volume: Vec<f64>,
}

impl Elements {
    fn of(mesh: &TetMesh) -> Self {
        let grads = mesh
            .dm_inv
            .iter()
            .map(|m| {
                let t = m.transpose();
                let g = [t.x_axis, t.y_axis, t.z_axis].map(|c| c.as_dvec3());
                [-(g[0] + g[1] + g[2]), g[0], g[1], g[2]]
            })
            .collect();
        let volume = mesh.rest_volume.iter().map(|&v| v as f64).collect();
        Self { grads, volume }
    }
}

/// `K u` for displacements `u`: the elastic forces' negative, assembled tet by tet.
fn apply_stiffness(mesh: &TetMesh, el: &Elements, lame: (f64, f64), u: &[DVec3]) -> Vec<DVec3> {
    let (mu, lambda) = lame;
    let mut out = vec![DVec3::ZERO; u.len()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        let g = &el.grads[t];
        // Displacement gradient H = Σ_a u_a ⊗ ∇_a, kept as its rows' outer products.
        let mut h = [[0.0f64; 3]; 3];
        for a in 0..4 {
            let ua = u[tet[a] as usize].to_array();
            let ga = g[a].to_array();
            for (i, row) in h.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v += ua[i] * ga[j];
                }
            }
        }
        let tr = h[0][0] + h[1][1] + h[2][2];
        let sigma =
            |i: usize, j: usize| mu * (h[i][j] + h[j][i]) + if i == j { lambda * tr } else { 0.0 };
        for a in 0..4 {
            let ga = g[a].to_array();
            let f = DVec3::from_array(std::array::from_fn(|i| {
                (0..3).map(|j| sigma(i, j) * ga[j]).sum::<f64>()
            }));
            out[tet[a] as usize] += el.volume[t] * f;
        }
    }
    out
}

/// The diagonal of `K` per node and axis: `V (μ|∇_a|² + (μ + λ) ∇_a,i²)` summed over tets.
fn stiffness_diagonal(mesh: &TetMesh, el: &Elements, lame: (f64, f64)) -> Vec<DVec3> {
    let (mu, lambda) = lame;
    let mut d = vec![DVec3::ZERO; mesh.node_count()];
    for (t, tet) in mesh.tets.iter().enumerate() {
        for a in 0..4 {
            let g = el.grads[t][a];
            d[tet[a] as usize] += el.volume[t] * (mu * g.length_squared() + (mu + lambda) * g * g);
        }
    }
    d
}

/// Dot product over the free nodes.
fn dot(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum()
}

/// Static displacement under nodal `loads` (N) with the nodes where `pinned` is true held
/// at zero; the conjugate-gradient residual falls below 1e-10 of the load or it panics.
pub fn static_displacement(
    mesh: &TetMesh,
    lame: Lame,
    loads: &[DVec3],
    pinned: &[bool],
) -> Vec<DVec3> {
    let el = Elements::of(mesh);
    let lame = (lame.mu as f64, lame.lambda as f64);
    let free = |v: &mut [DVec3]| {
        for (x, &p) in v.iter_mut().zip(pinned) {
            if p {
                *x = DVec3::ZERO;
            }
        }
    };
    let diag = stiffness_diagonal(mesh, &el, lame);
    let precondition =
        |r: &[DVec3]| -> Vec<DVec3> { r.iter().zip(&diag).map(|(r, d)| *r / *d).collect() };
    let mut u = vec![DVec3::ZERO; loads.len()];
    let mut r = loads.to_vec();
    free(&mut r);
    let mut z = precondition(&r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let target = 1e-10 * dot(&r, &r).sqrt();
    for _ in 0..20 * loads.len() {
        let mut kp = apply_stiffness(mesh, &el, lame, &p);
        free(&mut kp);
        let alpha = rz / dot(&p, &kp);
        for i in 0..u.len() {
            u[i] += alpha * p[i];
            r[i] -= alpha * kp[i];
        }
        if dot(&r, &r).sqrt() < target {
            return u;
        }
        z = precondition(&r);
        let rz_next = dot(&r, &z);
        let beta = rz_next / rz;
        rz = rz_next;
        for i in 0..p.len() {
            p[i] = z[i] + beta * p[i];
        }
    }
    panic!("linear FEM: conjugate gradients did not converge");
}
