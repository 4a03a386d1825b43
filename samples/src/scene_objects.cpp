// SPDX-License-Identifier: MIT
// SceneBuilder's objects: particle sets, springs, FEM and spring grids, rigid bodies, chains
// and cloth, each adding its bodies, force fields, constraints and stiffness bound.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>

#include "builders.hpp"
#include "scene_builder.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::samples::detail {

// Up to this many particles, the contact radius comes from the exact closest pair.
constexpr Index kExactSpacingPoints = 2048;

// `units` in order, cut into up to `split` consecutive runs; make(name, run) builds a field.
template <class Unit, class Make>
void SceneBuilder::add_split_fields(const std::string& name, const std::vector<Unit>& units, int split, Make make) {
  const std::size_t per = (units.size() + static_cast<std::size_t>(split) - 1) / static_cast<std::size_t>(split);
  if (split <= 1 || per >= units.size()) {
    scene_->add_force_field(make(name, units.begin(), units.end()));
    return;
  }
  int block = 0;
  for (std::size_t start = 0; start < units.size(); start += per, ++block)
    scene_->add_force_field(make(name + "[" + std::to_string(block) + "]",
                                 units.begin() + static_cast<std::ptrdiff_t>(start),
                                 units.begin() + static_cast<std::ptrdiff_t>(std::min(units.size(), start + per))));
}

void SceneBuilder::particles(Directive& d) {
  const std::string name = d.text("name");
  check_new_name(d, name);
  const std::string spec = d.text("points");
  std::vector<Vec3> pts;
  std::size_t start = 0;
  while (start <= spec.size()) {
    const std::size_t semi = spec.find(';', start);
    const auto v = d.numbers("points", 3, spec.substr(start, semi == std::string::npos ? std::string::npos : semi - start));
    pts.emplace_back(v[0], v[1], v[2]);
    add_points(d, 1);
    if (semi == std::string::npos) break;
    start = semi + 1;
  }
  StateVec x(3, static_cast<Index>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) x.col(static_cast<Index>(i)) = pts[i];
  const double mass = d.positive("mass");
  auto body = std::make_unique<ParticleBody>(name, x, std::vector<double>(pts.size(), mass));
  for (Index i = 0; i < x.cols(); ++i) body->surface.push_back(i);
  Body& b = scene_->add_body(std::move(body));
  double spacing = 0.1;
  if (x.cols() > 1 && x.cols() <= kExactSpacingPoints) {
    spacing = 1e300;
    for (Index i = 0; i < x.cols(); ++i)
      for (Index j = i + 1; j < x.cols(); ++j) spacing = std::min(spacing, (x.col(i) - x.col(j)).norm());
  } else if (x.cols() > kExactSpacingPoints) {
    // The closest pair costs n^2/2 distances: estimate from the bounding box instead.
    const Vec3 extent = x.rowwise().maxCoeff() - x.rowwise().minCoeff();
    spacing = extent.norm() / std::cbrt(static_cast<double>(x.cols()));
  }
  common(d, b, spacing);
  add_gravity(b);
  add_fix(b, fixed_nodes(d, x, d.text("fix", "none")));
}

void SceneBuilder::springs(Directive& d) {
  Body* a = body_by_name(d, "a");
  Body* b = d.has("b") ? body_by_name(d, "b") : nullptr;
  if (b == a) b = nullptr;
  const std::string name = d.text("name", b ? "springs[" + a->name() + "|" + b->name() + "]" : a->name() + ".springs");
  check_new_name(d, name);
  const double k = d.positive("stiffness");
  const std::optional<double> rest = d.has("rest") ? std::optional<double>(d.non_negative("rest")) : std::nullopt;
  std::vector<Spring> springs;
  const std::string spec = d.text("pairs");
  std::size_t start = 0;
  Body* other = b ? b : a;
  while (start <= spec.size()) {
    const std::size_t comma = spec.find(',', start);
    const std::string pair = spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto dash = pair.find('-');
    if (dash == std::string::npos) d.fail("pairs: '" + pair + "' is not i-j");
    Index i = 0, j = 0;
    auto r1 = std::from_chars(pair.data(), pair.data() + dash, i);
    auto r2 = std::from_chars(pair.data() + dash + 1, pair.data() + pair.size(), j);
    if (r1.ec != std::errc() || r1.ptr != pair.data() + dash || r2.ec != std::errc() ||
        r2.ptr != pair.data() + pair.size())
      d.fail("pairs: '" + pair + "' is not i-j");
    if (i < 0 || i >= a->num_points() || j < 0 || j >= other->num_points())
      d.fail("pairs: '" + pair + "' names a point out of range");
    springs.push_back({i, j, rest ? *rest : (a->point(i) - other->point(j)).norm(), k});
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  bound_.springs(name, springs, *a, b);
  scene_->add_force_field(std::make_unique<SpringForceField>(name, a, b, std::move(springs)));
}

// fem and springgrid: a hexahedral grid (box or ellipsoid).
void SceneBuilder::grid_object(Directive& d) {
  const bool fem = d.keyword() == "fem";
  const std::string name = d.text("name");
  const auto nodes = d.int3("nodes", std::nullopt, 2, 512);
  const std::uint64_t grid_nodes = static_cast<std::uint64_t>(nodes[0]) * nodes[1] * nodes[2];
  if (grid_nodes > (1u << 22)) d.fail("nodes: at most 4194304 nodes per object");
  const auto copies = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
  add_points(d, grid_nodes * static_cast<std::uint64_t>(copies[0]) * copies[1] * copies[2]);
  const Vec3 size = d.vec3("size");
  if ((size.array() <= 0.0).any()) d.fail("size: every extent must be > 0");
  const Vec3 center = d.vec3("center", Vec3::Zero());
  const Shape shape = d.choice("shape", "box", {"box", "ellipsoid"}) == "ellipsoid" ? Shape::kEllipsoid : Shape::kBox;
  const double density = d.positive("density", 1000.0);
  FemMaterial mat;
  double k = 0.0;
  if (fem) {
    mat.young = d.positive("young", 1e6);
    mat.poisson = d.number("poisson", 0.3);
    if (!(mat.poisson >= 0.0 && mat.poisson < 0.5)) d.fail("poisson must be in [0, 0.5)");
    mat.incompatible_modes = d.choice("element", "incompatible", {"incompatible", "trilinear"}) == "incompatible";
  } else {
    k = d.positive("stiffness");
  }
  const std::string fix = d.text("fix", "none");
  const int split = split_of(d);
  const HexMesh proto = detail::make_hex_grid(nodes, size, Vec3::Zero(), shape);
  if (proto.elements.empty()) d.fail("the shape contains no element (use more nodes)");
  const std::vector<Spring> springs = fem ? std::vector<Spring>{} : detail::grid_springs(proto, k);
  // Gershgorin rows of one instance (all instances are copies of the prototype).
  std::vector<double> rows(proto.node_volume.size(), 0.0);
  if (fem) {
    Eigen::Matrix<double, 3, 8> corners;
    for (int i = 0; i < 8; ++i) corners.col(i) = proto.nodes.col(proto.elements[0][static_cast<std::size_t>(i)]);
    const double row = HexFemForceField::element_stiffness(corners, mat).cwiseAbs().rowwise().sum().maxCoeff();
    for (const auto& e : proto.elements)
      for (Index n : e) rows[static_cast<std::size_t>(n)] += row;
  } else {
    for (const Spring& sp : springs) {
      rows[static_cast<std::size_t>(sp.i)] += 2.0 * sp.stiffness;
      rows[static_cast<std::size_t>(sp.j)] += 2.0 * sp.stiffness;
    }
  }
  bool first = true;
  for (const auto& [inst, c] : instances(d, name, center)) {
    check_new_name(d, inst);
    StateVec x = proto.nodes;
    x.colwise() += c;
    std::vector<double> masses(proto.node_volume.size());
    for (std::size_t i = 0; i < masses.size(); ++i) masses[i] = density * proto.node_volume[i];
    auto body = std::make_unique<ParticleBody>(inst, x, std::move(masses));
    ParticleBody* pb = body.get();
    if (first) bound_.body_rows(inst, rows, *pb);
    pb->surface = proto.surface;
    pb->triangles = proto.triangles;
    scene_->add_body(std::move(body));
    instance_common(d, *pb, proto.spacing.minCoeff(), first);
    first = false;
    add_gravity(*pb);
    if (fem && split > 1) {
      const HexFemForceField whole(inst + ".fem", pb, proto.elements, mat);
      add_split_fields(inst + ".fem", whole.element_batches(), split, [&](const std::string& n, auto run_begin, auto run_end) {
        std::vector<std::array<Index, 8>> elements;
        for (auto it = run_begin; it != run_end; ++it) elements.insert(elements.end(), it->begin(), it->end());
        return std::make_unique<HexFemForceField>(n, pb, std::move(elements), mat, &whole);
      });
    } else if (fem) {
      scene_->add_force_field(std::make_unique<HexFemForceField>(inst + ".fem", pb, proto.elements, mat));
    } else {
      add_split_fields(inst + ".springs", springs, split, [&](const std::string& n, auto run_begin, auto run_end) {
        return std::make_unique<SpringForceField>(n, pb, nullptr, std::vector<Spring>(run_begin, run_end));
      });
    }
    add_fix(*pb, fixed_nodes(d, x, fix));
  }
}

void SceneBuilder::rigid(Directive& d) {
  const std::string name = d.text("name");
  const std::string shape = d.choice("shape", "box", {"box", "sphere"});
  const int res = d.integer("res", 8, 2, 256);
  const double density = d.positive("density", 1000.0);
  const Vec3 center = d.vec3("center", Vec3::Zero());
  detail::RigidSurface surf;
  double mass = 0.0;
  Mat3 inertia = Mat3::Zero();
  if (shape == "box") {
    const Vec3 size = d.vec3("size");
    if ((size.array() <= 0.0).any()) d.fail("size: every extent must be > 0");
    surf = detail::box_surface(size, res);
    mass = density * size.prod();
    inertia.diagonal() << mass / 12.0 * (size.y() * size.y() + size.z() * size.z()),
        mass / 12.0 * (size.x() * size.x() + size.z() * size.z()),
        mass / 12.0 * (size.x() * size.x() + size.y() * size.y());
  } else {
    const double r = d.positive("size");
    surf = detail::sphere_surface(r, res);
    mass = density * 4.0 / 3.0 * M_PI * r * r * r;
    inertia = Mat3::Identity() * (0.4 * mass * r * r);
  }
  {
    const auto copies = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
    add_points(d, static_cast<std::uint64_t>(surf.points.cols()) * copies[0] * copies[1] * copies[2]);
  }
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  if (d.has("rotation")) {
    const auto v = d.numbers("rotation", 4, d.text("rotation"));
    const Vec3 axis(v[0], v[1], v[2]);
    if (axis.norm() == 0.0) d.fail("rotation: the axis must not be zero");
    q = Eigen::AngleAxisd(v[3] * M_PI / 180.0, axis.normalized());
  }
  const double spin = d.non_negative("spin", 0.0);
  const bool fixed = d.choice("fix", "none", {"none", "all"}) == "all";
  bool first = true;
  for (const auto& [inst, c] : instances(d, name, center)) {
    check_new_name(d, inst);
    Eigen::Quaterniond qi = q;
    if (spin > 0.0) {
      Vec3 axis = jitter_.vec();
      if (axis.norm() < 1e-6) axis = Vec3::UnitY();
      qi = Eigen::AngleAxisd(spin * jitter_.uniform() * M_PI / 180.0, axis.normalized()) * q;
    }
    auto body = std::make_unique<RigidBody>(inst, mass, inertia, c, qi, surf.points);
    RigidBody* rb = body.get();
    for (Index i = 0; i < surf.points.cols(); ++i) rb->surface.push_back(i);
    rb->triangles = surf.triangles;
    scene_->add_body(std::move(body));
    instance_common(d, *rb, surf.spacing, first);
    first = false;
    if (fixed)
      add_fix(*rb, {0, 1});
    else
      add_gravity(*rb);
  }
}

// A serpentine chain of particles (the torso's intestine): stretch and bending springs;
// `array=` makes copies (name0, name1, ...) like the grid objects.
void SceneBuilder::chain(Directive& d) {
  const std::string name = d.text("name");
  const int n = d.integer("nodes", std::nullopt, 3, 1000000);
  {
    const auto copies = d.int3("array", std::array<int, 3>{1, 1, 1}, 1, 4096);
    add_points(d, static_cast<std::uint64_t>(n) * copies[0] * copies[1] * copies[2]);
  }
  const int rows = d.integer("rows", 1, 1, n);
  const double seg = d.positive("segment");
  const Vec3 center = d.vec3("center", Vec3::Zero());
  const double k = d.positive("stiffness");
  const double kb = d.non_negative("bend", 0.0);
  const double mass = d.positive("mass");
  const int per_row = (n + rows - 1) / rows;
  StateVec proto(3, n);
  const double width = seg * (per_row - 1);
  const double row_gap = d.positive("row_gap", 2.0 * seg);
  for (int i = 0; i < n; ++i) {
    const int row = i / per_row;
    int col = i % per_row;
    if (row % 2 == 1) col = per_row - 1 - col;
    proto.col(i) = Vec3(col * seg - 0.5 * width, 0.0, row * row_gap - 0.5 * row_gap * (rows - 1));
  }
  std::vector<Spring> springs;
  for (Index i = 0; i + 1 < n; ++i) springs.push_back({i, i + 1, (proto.col(i + 1) - proto.col(i)).norm(), k});
  if (kb > 0.0)
    for (Index i = 0; i + 2 < n; ++i) springs.push_back({i, i + 2, (proto.col(i + 2) - proto.col(i)).norm(), kb});
  const std::string fix = d.text("fix", "none");
  const int split = split_of(d);
  bool first = true;
  for (const auto& [inst, c] : instances(d, name, center)) {
    check_new_name(d, inst);
    StateVec x = proto;
    x.colwise() += c;
    auto body = std::make_unique<ParticleBody>(inst, x, std::vector<double>(static_cast<std::size_t>(n), mass / n));
    for (Index i = 0; i < n; ++i) body->surface.push_back(i);
    Body& b = scene_->add_body(std::move(body));
    if (first) bound_.springs(inst, springs, b, nullptr);
    instance_common(d, b, seg, first);
    first = false;
    add_gravity(b);
    add_split_fields(inst + ".springs", springs, split, [&](const std::string& fn, auto run_begin, auto run_end) {
      return std::make_unique<SpringForceField>(fn, &b, nullptr, std::vector<Spring>(run_begin, run_end));
    });
    add_fix(b, fixed_nodes(d, x, fix));
  }
}

// An N x N mass-spring sheet cut into split x split sub-objects joined by interaction
// springs (the paper's domain decomposition, section 4.3).
void SceneBuilder::cloth(Directive& d) {
  const std::string name = d.text("name");
  const int n = d.integer("nodes", std::nullopt, 2, 2048);
  int split = d.integer("split", 4, 1, 1024);
  if (options_.subobjects) {
    const int s = static_cast<int>(std::lround(std::sqrt(static_cast<double>(*options_.subobjects))));
    if (*options_.subobjects < 1 || s * s != *options_.subobjects)
      throw OptionError("subobjects", "must be a perfect square (1, 4, 9, 16, ...)");
    split = s;
  }
  if (split > n) d.fail("split must not exceed nodes");
  add_points(d, static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(n));
  const double size = d.positive("size");
  const Vec3 center = d.vec3("center", Vec3::Zero());
  const double k = d.positive("stiffness");
  const double ks = d.non_negative("shear", 0.5 * k);
  const double kb = d.non_negative("bend", 0.0);
  const double total_mass = d.positive("mass");
  const double damping = d.non_negative("damping", 0.0);
  const std::string fix = d.choice("fix", "corners", {"none", "corners", "edge"});
  const double h = size / (n - 1);
  auto block_of = [&](int i) { return static_cast<int>(static_cast<long long>(i) * split / n); };
  // Local numbering inside each block.
  std::vector<int> block(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  std::vector<Index> local(block.size());
  std::vector<std::vector<Vec3>> pos(static_cast<std::size_t>(split * split));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int bidx = block_of(i) + split * block_of(j);
      const std::size_t node = static_cast<std::size_t>(i) + static_cast<std::size_t>(n) * static_cast<std::size_t>(j);
      block[node] = bidx;
      auto& p = pos[static_cast<std::size_t>(bidx)];
      local[node] = static_cast<Index>(p.size());
      p.push_back(center + Vec3(i * h - 0.5 * size, 0.0, j * h - 0.5 * size));
    }
  std::vector<ParticleBody*> bodies;
  const double node_mass = total_mass / (static_cast<double>(n) * n);
  for (int bj = 0; bj < split; ++bj)
    for (int bi = 0; bi < split; ++bi) {
      const std::string bname = split == 1 ? name : name + "_" + std::to_string(bi) + "_" + std::to_string(bj);
      check_new_name(d, bname);
      const auto& p = pos[static_cast<std::size_t>(bi + split * bj)];
      StateVec x(3, static_cast<Index>(p.size()));
      for (std::size_t v = 0; v < p.size(); ++v) x.col(static_cast<Index>(v)) = p[v];
      auto body = std::make_unique<ParticleBody>(bname, x, std::vector<double>(p.size(), node_mass));
      body->mass_damping = damping;
      bodies.push_back(body.get());
      scene_->add_body(std::move(body));
    }
  for (ParticleBody* b : bodies) add_gravity(*b);
  // Springs, sorted into internal fields and interaction fields by the blocks they join.
  std::vector<std::vector<Spring>> internal(bodies.size());
  std::map<std::pair<int, int>, std::vector<Spring>> ties;
  std::vector<double> rows(block.size(), 0.0);
  auto add = [&](int i0, int j0, int i1, int j1, double stiffness) {
    if (stiffness <= 0.0 || i1 < 0 || i1 >= n || j1 >= n) return;
    const std::size_t a = static_cast<std::size_t>(i0) + static_cast<std::size_t>(n) * static_cast<std::size_t>(j0);
    const std::size_t b = static_cast<std::size_t>(i1) + static_cast<std::size_t>(n) * static_cast<std::size_t>(j1);
    rows[a] += 2.0 * stiffness;
    rows[b] += 2.0 * stiffness;
    const double rest = h * std::hypot(i1 - i0, j1 - j0);
    if (block[a] == block[b]) {
      internal[static_cast<std::size_t>(block[a])].push_back({local[a], local[b], rest, stiffness});
    } else if (block[a] < block[b]) {
      ties[{block[a], block[b]}].push_back({local[a], local[b], rest, stiffness});
    } else {
      ties[{block[b], block[a]}].push_back({local[b], local[a], rest, stiffness});
    }
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      add(i, j, i + 1, j, k);
      add(i, j, i, j + 1, k);
      add(i, j, i + 1, j + 1, ks);
      add(i + 1, j, i, j + 1, ks);
      add(i, j, i + 2, j, kb);
      add(i, j, i, j + 2, kb);
    }
  for (const double row : rows) bound_.node(name, row, node_mass);
  for (std::size_t b = 0; b < bodies.size(); ++b)
    scene_->add_force_field(
        std::make_unique<SpringForceField>(bodies[b]->name() + ".springs", bodies[b], nullptr, std::move(internal[b])));
  for (auto& [key, springs] : ties) {
    ParticleBody* a = bodies[static_cast<std::size_t>(key.first)];
    ParticleBody* b = bodies[static_cast<std::size_t>(key.second)];
    scene_->add_force_field(std::make_unique<SpringForceField>("ties[" + a->name() + "|" + b->name() + "]", a, b,
                                                               std::move(springs)));
  }
  // Fixed nodes: the two corners of the first row, or the whole first row.
  std::map<int, std::vector<Index>> fixed;
  if (fix == "corners") {
    for (int i : {0, n - 1}) fixed[block[static_cast<std::size_t>(i)]].push_back(local[static_cast<std::size_t>(i)]);
  } else if (fix == "edge") {
    for (int i = 0; i < n; ++i) fixed[block[static_cast<std::size_t>(i)]].push_back(local[static_cast<std::size_t>(i)]);
  }
  for (auto& [bidx, cols] : fixed) add_fix(*bodies[static_cast<std::size_t>(bidx)], std::move(cols));
}

}  // namespace tgraph::samples::detail
