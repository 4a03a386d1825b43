// SPDX-License-Identifier: MIT
// Force fields: each provides addForce (f += f(x, v)) and addDForce (df += k K dx).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "tgraph/samples/body.hpp"

namespace tgraph::samples {

/// A force field acting on one body, or an interaction between two bodies.
///
/// K = df/dx is the stiffness (negative semi-definite for every field here, so that the
/// implicit solver's matrix M - h^2 K stays positive definite).
class ForceField {
 public:
  /// Field acting on `a` (and `b` for an interaction).
  ForceField(std::string name, Body* a, Body* b = nullptr);
  virtual ~ForceField() = default;
  ForceField(const ForceField&) = delete;
  ForceField& operator=(const ForceField&) = delete;

  /// Name, stable across steps.
  const std::string& name() const { return name_; }
  /// First (or only) body.
  Body* body_a() const { return a_; }
  /// Second body of an interaction, else nullptr.
  Body* body_b() const { return b_; }
  /// True for a field between two bodies.
  bool is_interaction() const { return b_ != nullptr; }

  /// f += f(x, v) on the field's bodies; caches what addDForce needs (state()).
  virtual void add_force() = 0;
  /// vec(df) += (k_factor K + b_factor B) vec(dx) on the field's bodies, with K = df/dx and
  /// B = df/dv (damping) from the last add_force().
  virtual void add_dforce(VecId df, VecId dx, double k_factor, double b_factor = 0.0);
  /// True when add_dforce does anything (fields with stiffness).
  virtual bool has_stiffness() const { return false; }
  /// True when add_force reads velocities.
  virtual bool reads_velocity() const { return false; }
  /// True when add_force reads positions.
  virtual bool reads_position() const { return true; }
  /// Bytes of the state cached by add_force for add_dforce (0 = none); it is a datum of the
  /// task graph, written by addForce and read by addDForce.
  virtual std::uint64_t state_bytes() const { return 0; }
  /// Pointer to that cached state (for live replay), or nullptr.
  virtual void* state_ptr() { return nullptr; }
  /// Potential energy at the current positions.
  virtual double potential_energy() const { return 0.0; }

 private:
  std::string name_;
  Body* a_;
  Body* b_;
};

/// Gravity: f += M g (the paper's "accumulate").
class GravityForceField final : public ForceField {
 public:
  GravityForceField(std::string name, Body* body, const Vec3& g);
  void add_force() override;
  bool reads_position() const override { return false; }
  double potential_energy() const override;

 private:
  Vec3 g_;
};

/// One spring between point i of body a and point j of body b (or of a itself).
struct Spring {
  Index i = 0;
  Index j = 0;
  double rest = 0.0;
  double stiffness = 0.0;
};

/// Linear springs between the nodes of one body or between two bodies (interaction springs
/// tying sub-objects of a decomposed mesh, or the spring of the paper's Figure 2).
///
/// Stiffness: K = -k [ n n^T + max(0, 1 - l0/l) (I - n n^T) ]; the compressive part of the
/// geometric term is dropped so that K stays negative semi-definite.
class SpringForceField final : public ForceField {
 public:
  /// Springs within `a` (b == nullptr) or between `a` and `b`.
  SpringForceField(std::string name, Body* a, Body* b, std::vector<Spring> springs);
  void add_force() override;
  void add_dforce(VecId df, VecId dx, double k_factor, double b_factor = 0.0) override;
  bool has_stiffness() const override { return true; }
  std::uint64_t state_bytes() const override;
  void* state_ptr() override { return cache_.data(); }
  double potential_energy() const override;
  /// The springs.
  const std::vector<Spring>& springs() const { return springs_; }

 private:
  struct Cache {
    Vec3 n = Vec3::Zero();  // unit direction from i to j
    double geo = 0.0;      // max(0, 1 - l0/l)
  };
  template <bool kSame>
  void add_force_impl();
  template <bool kSame>
  void add_dforce_impl(VecId df, VecId dx, double k_factor);

  std::vector<Spring> springs_;
  std::vector<Cache> cache_;
  bool particles_ = false;  // both ends are ParticleBody nodes (fast path)
};

/// Material and element options of the hexahedral FEM.
struct FemMaterial {
  double young = 1e6;    ///< Young's modulus (Pa)
  double poisson = 0.3;  ///< Poisson's ratio
  /// Incompatible modes (Wilson-Taylor, statically condensed into the 24x24 matrix): the
  /// trilinear hexahedron then bends without shear locking.
  bool incompatible_modes = true;
};

/// Hexahedral finite elements, linear elasticity with the corotational formulation: each
/// element's rotation R is the rotation of the polar decomposition of its deformation
/// gradient at the element centre (extracted iteratively, warm-started per element), and f_e = -R K_e (R^T x_e - X_e), K = -R K_e R^T. The 24x24 element
/// stiffness matrices are precomputed (shared by elements of identical rest shape).
class HexFemForceField final : public ForceField {
 public:
  /// Elements given as 8 node indices each, in the order (x,y,z) = (0,0,0), (1,0,0),
  /// (1,1,0), (0,1,0), (0,0,1), (1,0,1), (1,1,1), (0,1,1) of the reference cube.
  /// With `whole` (the unsplit field of a split object), the element matrices of shapes it
  /// has are taken from it rather than recomputed from this field's first element of that
  /// shape, so that a split field computes exactly what the whole one does.
  HexFemForceField(std::string name, ParticleBody* body, std::vector<std::array<Index, 8>> elements,
                   const FemMaterial& material, const HexFemForceField* whole = nullptr);
  void add_force() override;
  void add_dforce(VecId df, VecId dx, double k_factor, double b_factor = 0.0) override;
  bool has_stiffness() const override { return true; }
  std::uint64_t state_bytes() const override;
  void* state_ptr() override { return rotations_.data(); }
  double potential_energy() const override;
  /// Number of elements.
  std::size_t num_elements() const { return elements_.size(); }
  /// Elements of one stiffness matrix processed together (one 24 x kBatch product); a
  /// field split into element ranges that are multiples of it adds the same terms in the
  /// same order as the whole field.
  static constexpr int kBatch = 32;
  /// The elements in the batches add_force processes, in order (up to kBatch elements of
  /// one stiffness matrix each). Fields made of consecutive runs of these batches, run one
  /// after the other, add the same terms into every node in the same order as this field.
  std::vector<std::vector<std::array<Index, 8>>> element_batches() const;

  using Mat24 = Eigen::Matrix<double, 24, 24>;
  /// The 24x24 stiffness matrix of a hexahedron with rest corners `rest` (3 x 8).
  static Mat24 element_stiffness(const Eigen::Matrix<double, 3, 8>& rest, const FemMaterial& material);

 private:
  ParticleBody* body_;
  std::vector<std::array<Index, 8>> elements_;
  std::vector<Eigen::Matrix<double, 3, 8>> rest_;        // rest corners per element
  std::vector<Eigen::Matrix<double, 3, 8>> grad_;        // shape gradients at the centre
  std::vector<Mat24, Eigen::aligned_allocator<Mat24>> ke_;  // distinct element matrices
  std::vector<std::array<long long, 24>> ke_keys_;       // shape key of each matrix
  std::vector<std::uint32_t> ke_index_;                  // element -> matrix
  std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>> batches_;  // matrix -> elements
  std::vector<Mat3> rotations_;                          // cached by add_force
  std::vector<Eigen::Quaterniond> quats_;                // same, warm start of the extraction
};

/// One penalty contact between point i of body a and point j of body b.
struct ContactPair {
  Index i = 0;
  Index j = 0;
};

/// Penalty contact springs between two bodies' surface points (sphere proxies of radius
/// ra + rb): f = k max(0, ra + rb - d) n, K = -k n n^T while in contact, plus viscous
/// damping of the relative normal velocity (c_n) and of the sliding velocity (c_t):
/// B = -c_n n n^T - c_t (I - n n^T), treated implicitly by the implicit solver.
/// The pairs are maintained by the collision pipeline; the field exists while the bodies
/// are in proximity.
class ContactForceField final : public ForceField {
 public:
  ContactForceField(std::string name, Body* a, Body* b, double stiffness, double damping = 0.0,
                    double friction = 0.0);
  bool reads_velocity() const override { return damping_ > 0.0 || friction_ > 0.0; }
  void add_force() override;
  void add_dforce(VecId df, VecId dx, double k_factor, double b_factor = 0.0) override;
  bool has_stiffness() const override { return true; }
  std::uint64_t state_bytes() const override;
  void* state_ptr() override { return cache_.data(); }
  double potential_energy() const override;
  /// Replaces the contact pairs (collision detection; outside the task graph).
  void set_pairs(std::vector<ContactPair> pairs);
  /// Current pairs.
  const std::vector<ContactPair>& pairs() const { return pairs_; }

 private:
  struct Cache {
    Vec3 n = Vec3::Zero();
    bool active = false;
  };
  double stiffness_;
  double damping_;
  double friction_;
  std::vector<ContactPair> pairs_;
  std::vector<Cache> cache_;
};

/// Penalty contact of a body's surface points with a static floor plane y = height, with
/// viscous damping of the normal velocity and of the sliding velocity (B as for contacts).
class FloorContactForceField final : public ForceField {
 public:
  FloorContactForceField(std::string name, Body* body, double height, double stiffness,
                         double friction_damping, double normal_damping = 0.0);
  void add_force() override;
  void add_dforce(VecId df, VecId dx, double k_factor, double b_factor = 0.0) override;
  bool has_stiffness() const override { return true; }
  bool reads_velocity() const override { return friction_damping_ > 0.0 || normal_damping_ > 0.0; }
  std::uint64_t state_bytes() const override;
  void* state_ptr() override { return active_.data(); }
  double potential_energy() const override;
  /// Replaces the surface points near the floor (collision detection).
  void set_points(std::vector<Index> points);
  /// Points near the floor.
  const std::vector<Index>& points() const { return points_; }
  /// Height of the plane.
  double height() const { return height_; }

 private:
  double height_;
  double stiffness_;
  double friction_damping_;
  double normal_damping_;
  std::vector<Index> points_;
  std::vector<char> active_;
};

}  // namespace tgraph::samples
