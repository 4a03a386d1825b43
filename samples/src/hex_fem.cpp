// SPDX-License-Identifier: MIT
// Corotational hexahedral FEM (linear elasticity in each element's rotated frame).
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "tgraph/samples/force_field.hpp"

namespace tgraph::samples {
namespace {

using Mat38 = Eigen::Matrix<double, 3, 8>;
using Vec24 = Eigen::Matrix<double, 24, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// Reference corner coordinates, in the documented node order.
constexpr std::array<std::array<double, 3>, 8> kCorner = {{{-1, -1, -1},
                                                           {1, -1, -1},
                                                           {1, 1, -1},
                                                           {-1, 1, -1},
                                                           {-1, -1, 1},
                                                           {1, -1, 1},
                                                           {1, 1, 1},
                                                           {-1, 1, 1}}};

// Derivatives of the 8 trilinear shape functions w.r.t. the reference coordinates (3 x 8).
Mat38 shape_derivatives(double xi, double eta, double zeta) {
  Mat38 d;
  for (int i = 0; i < 8; ++i) {
    const auto& corner = kCorner[static_cast<std::size_t>(i)];
    const double a = corner[0], b = corner[1], c = corner[2];
    d(0, i) = 0.125 * a * (1 + eta * b) * (1 + zeta * c);
    d(1, i) = 0.125 * b * (1 + xi * a) * (1 + zeta * c);
    d(2, i) = 0.125 * c * (1 + xi * a) * (1 + eta * b);
  }
  return d;
}

Mat6 elasticity(const FemMaterial& m) {
  const double lambda = m.young * m.poisson / ((1 + m.poisson) * (1 - 2 * m.poisson));
  const double mu = m.young / (2 * (1 + m.poisson));
  Mat6 d = Mat6::Zero();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) d(i, j) = lambda;
    d(i, i) = lambda + 2 * mu;
    d(3 + i, 3 + i) = mu;
  }
  return d;
}

// Strain-displacement rows for one gradient vector g (Voigt: xx yy zz xy yz zx).
void fill_b(Eigen::Ref<Eigen::Matrix<double, 6, 3>> b, const Vec3& g) {
  b.setZero();
  b(0, 0) = g.x();
  b(1, 1) = g.y();
  b(2, 2) = g.z();
  b(3, 0) = g.y();
  b(3, 1) = g.x();
  b(4, 1) = g.z();
  b(4, 2) = g.y();
  b(5, 0) = g.z();
  b(5, 2) = g.x();
}

// Rotation R of the polar decomposition F = R S, warm-started with the element's previous
// rotation q. Newton iteration on the rotation vector: with M = R^T F and S = sym(M), the
// correction theta solving (tr(S) I - S) theta = axial(M - M^T) makes R exp(theta)^T F
// symmetric to first order (quadratic convergence: one or two iterations per step). Where
// tr(S) I - S is not safely positive (inverted or strongly sheared elements), a damped
// step of Mueller et al. (MIG 2016) is taken instead, which maximises tr(R^T F).
Mat3 extract_rotation(const Mat3& f, Eigen::Quaterniond& q) {
  Mat3 r = q.toRotationMatrix();
  for (int it = 0; it < 40; ++it) {
    const Mat3 m = r.transpose() * f;
    const Vec3 skew(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
    const Mat3 sym = 0.5 * (m + m.transpose());
    const double tr = sym.trace();
    const Mat3 jac = tr * Mat3::Identity() - sym;
    Vec3 theta;
    const double det = jac.determinant();
    if (tr > 0.0 && det > 1e-3 * tr * tr * tr && (jac.diagonal().array() > 0.0).all())
      theta = jac.inverse() * skew;
    else
      theta = skew / (std::abs(tr) + 1e-300);
    const double w = theta.norm();
    if (!(w > 1e-12)) break;  // also stops on NaN input
    if (w > 1.0) theta /= w;  // at most one radian per iteration
    q = q * Eigen::Quaterniond(1.0, 0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z());
    q.normalize();
    r = q.toRotationMatrix();
  }
  return r;
}

}  // namespace

HexFemForceField::Mat24 HexFemForceField::element_stiffness(const Mat38& rest, const FemMaterial& material) {
  const Mat6 d = elasticity(material);
  const double gp = 1.0 / std::sqrt(3.0);
  Mat24 kuu = Mat24::Zero();
  Eigen::Matrix<double, 24, 9> kua = Eigen::Matrix<double, 24, 9>::Zero();
  Eigen::Matrix<double, 9, 9> kaa = Eigen::Matrix<double, 9, 9>::Zero();
  // Jacobian at the centre, for the incompatible modes (Taylor's patch-test correction).
  const Mat3 j0 = rest * shape_derivatives(0, 0, 0).transpose();
  const double det0 = j0.determinant();
  const Mat3 j0_inv_t = j0.inverse().transpose();
  for (int gi = 0; gi < 8; ++gi) {
    const auto& corner = kCorner[static_cast<std::size_t>(gi)];
    const double xi = corner[0] * gp, eta = corner[1] * gp, zeta = corner[2] * gp;
    const Mat38 dref = shape_derivatives(xi, eta, zeta);
    const Mat3 j = rest * dref.transpose();  // J_ab = sum_i X_i[a] dN_i/dxi_b
    const double det = j.determinant();
    const Mat38 grad = j.inverse().transpose() * dref;  // gradients w.r.t. X
    Eigen::Matrix<double, 6, 24> b;
    for (int i = 0; i < 8; ++i) fill_b(b.block<6, 3>(0, 3 * i), grad.col(i));
    kuu.noalias() += b.transpose() * d * b * det;
    if (material.incompatible_modes) {
      // Modes 1 - xi^2, 1 - eta^2, 1 - zeta^2 for each displacement component.
      const Vec3 dref_modes[3] = {Vec3(-2 * xi, 0, 0), Vec3(0, -2 * eta, 0), Vec3(0, 0, -2 * zeta)};
      Eigen::Matrix<double, 6, 9> g;
      for (int m = 0; m < 3; ++m)
        fill_b(g.block<6, 3>(0, 3 * m), (det0 / det) * (j0_inv_t * dref_modes[m]));
      kua.noalias() += b.transpose() * d * g * det;
      kaa.noalias() += g.transpose() * d * g * det;
    }
  }
  if (material.incompatible_modes) kuu.noalias() -= kua * kaa.ldlt().solve(kua.transpose());
  return 0.5 * (kuu + kuu.transpose());
}

HexFemForceField::HexFemForceField(std::string name, ParticleBody* body,
                                   std::vector<std::array<Index, 8>> elements, const FemMaterial& material,
                                   const HexFemForceField* whole)
    : ForceField(std::move(name), body), body_(body), elements_(std::move(elements)) {
  const StateVec& x0 = body->rest();
  const std::size_t ne = elements_.size();
  rest_.resize(ne);
  grad_.resize(ne);
  ke_index_.resize(ne);
  rotations_.assign(ne, Mat3::Identity());
  quats_.assign(ne, Eigen::Quaterniond::Identity());
  // Elements of identical rest shape (up to translation) share one stiffness matrix.
  std::map<std::array<long long, 24>, std::uint32_t> shapes;
  for (std::size_t e = 0; e < ne; ++e) {
    Mat38& r = rest_[e];
    for (int i = 0; i < 8; ++i) r.col(i) = x0.col(elements_[e][static_cast<std::size_t>(i)]);
    const Mat3 j = r * shape_derivatives(0, 0, 0).transpose();
    grad_[e] = j.inverse().transpose() * shape_derivatives(0, 0, 0);
    std::array<long long, 24> key{};
    const double scale = 1e-9 * std::max(1e-12, (r.col(6) - r.col(0)).norm());
    for (int i = 0; i < 8; ++i)
      for (int c = 0; c < 3; ++c)
        key[static_cast<std::size_t>(3 * i + c)] = std::llround((r(c, i) - r(c, 0)) / scale);
    auto [it, inserted] = shapes.emplace(key, static_cast<std::uint32_t>(ke_.size()));
    if (inserted) {
      const auto known = whole ? std::find(whole->ke_keys_.begin(), whole->ke_keys_.end(), key) : ke_keys_.end();
      ke_.push_back(whole && known != whole->ke_keys_.end()
                        ? whole->ke_[static_cast<std::size_t>(known - whole->ke_keys_.begin())]
                        : element_stiffness(r, material));
      ke_keys_.push_back(key);
    }
    ke_index_[e] = it->second;
  }
  batches_.resize(ke_.size());
  for (std::size_t k = 0; k < ke_.size(); ++k) batches_[k].first = static_cast<std::uint32_t>(k);
  for (std::size_t e = 0; e < ne; ++e) batches_[ke_index_[e]].second.push_back(static_cast<std::uint32_t>(e));
}

std::uint64_t HexFemForceField::state_bytes() const { return rotations_.size() * sizeof(Mat3); }

// Elements sharing one stiffness matrix are processed in batches of kBatch: their local
// (rotated) displacements form a 24 x kBatch matrix multiplied by K_e at once, which keeps
// K_e in registers and cache instead of streaming it once per element.
namespace {
constexpr int kBatch = HexFemForceField::kBatch;
using Batch = Eigen::Matrix<double, 24, kBatch>;

// For each batch of up to kBatch elements of one matrix K_e: gather(e, column) writes element
// e's 24 local values into its column of `in`, out = K_e in, then scatter(e, column) reads
// element e's 24 results from its column of `out`.
template <class Matrices, class Gather, class Scatter>
void for_each_batch(const std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>>& batches,
                    const Matrices& ke, Gather&& gather, Scatter&& scatter) {
  Batch in, out;
  for (const auto& [k, elems] : batches) {
    for (std::size_t start = 0; start < elems.size(); start += kBatch) {
      const int n = static_cast<int>(std::min<std::size_t>(kBatch, elems.size() - start));
      for (int c = 0; c < n; ++c) gather(elems[start + static_cast<std::size_t>(c)], in.col(c).data());
      out.leftCols(n).noalias() = ke[k] * in.leftCols(n);
      for (int c = 0; c < n; ++c) scatter(elems[start + static_cast<std::size_t>(c)], out.col(c).data());
    }
  }
}
}  // namespace

void HexFemForceField::add_force() {
  const StateVec& x = body_->vec(VecId::kX);
  StateVec& f = body_->vec(VecId::kF);
  for_each_batch(
      batches_, ke_,
      [&](std::uint32_t e, double* u) {
        const auto& nodes = elements_[e];
        Mat38 xe;
        for (int i = 0; i < 8; ++i) xe.col(i) = x.col(nodes[static_cast<std::size_t>(i)]);
        rotations_[e] = extract_rotation(xe * grad_[e].transpose(), quats_[e]);
        Eigen::Map<Mat38>{u} = rotations_[e].transpose() * xe - rest_[e];
      },
      [&](std::uint32_t e, const double* fe) {
        const auto& nodes = elements_[e];
        const Mat38 fw = -(rotations_[e] * Eigen::Map<const Mat38>(fe));
        for (int i = 0; i < 8; ++i) f.col(nodes[static_cast<std::size_t>(i)]) += fw.col(i);
      });
}

void HexFemForceField::add_dforce(VecId df, VecId dx, double k_factor, double /*b_factor*/) {
  const StateVec& in = body_->vec(dx);
  StateVec& out = body_->vec(df);
  for_each_batch(
      batches_, ke_,
      [&](std::uint32_t e, double* local) {
        const auto& nodes = elements_[e];
        Mat38 de;
        for (int i = 0; i < 8; ++i) de.col(i) = in.col(nodes[static_cast<std::size_t>(i)]);
        Eigen::Map<Mat38>{local} = rotations_[e].transpose() * de;
      },
      [&](std::uint32_t e, const double* fe) {
        const auto& nodes = elements_[e];
        const Mat38 fw = (-k_factor) * (rotations_[e] * Eigen::Map<const Mat38>(fe));
        for (int i = 0; i < 8; ++i) out.col(nodes[static_cast<std::size_t>(i)]) += fw.col(i);
      });
}

std::vector<std::vector<std::array<Index, 8>>> HexFemForceField::element_batches() const {
  std::vector<std::vector<std::array<Index, 8>>> out;
  for (const auto& [ke, elems] : batches_)
    for (std::size_t start = 0; start < elems.size(); start += kBatch) {
      auto& b = out.emplace_back();
      for (std::size_t c = start; c < std::min(elems.size(), start + kBatch); ++c) b.push_back(elements_[elems[c]]);
    }
  return out;
}

double HexFemForceField::potential_energy() const {
  const StateVec& x = body_->vec(VecId::kX);
  double energy = 0.0;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    Mat38 xe;
    for (int i = 0; i < 8; ++i) xe.col(i) = x.col(elements_[e][static_cast<std::size_t>(i)]);
    Eigen::Quaterniond q = quats_[e];
    const Mat3 rot = extract_rotation(xe * grad_[e].transpose(), q);
    Mat38 u = rot.transpose() * xe - rest_[e];
    const auto uv = Eigen::Map<const Vec24>(u.data());
    energy += 0.5 * uv.dot(ke_[ke_index_[e]] * uv);
  }
  return energy;
}

}  // namespace tgraph::samples
