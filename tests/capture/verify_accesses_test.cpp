// SPDX-License-Identifier: MIT
// Access verification in capture mode (Recorder::set_verify_accesses): a body writing a
// datum it declares R, one reading a datum it does not declare, and correct ones.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "tgraph/capture/recorder.hpp"

namespace tgraph::capture {
namespace {

using M = AccessMode;

struct Cells {
  std::array<double, 4> a{1.5, 2.5, 3.5, 4.5}, b{0.5, 0.25, 0.125, 2.0}, c{};
  double s = 0;
};

TEST(VerifyAccesses, NamesAWriteDeclaredReadAndAnUndeclaredRead) {
  Cells e;
  Recorder rec(Mode::kCapture);
  rec.set_verify_accesses(true);
  const ObjectId o = rec.object("tile(0,0)");
  const DatumId a = rec.datum("a", o, sizeof e.a, e.a.data());
  const DatumId b = rec.datum("b", o, sizeof e.b, e.b.data());
  const DatumId c = rec.datum("c", o, sizeof e.c, e.c.data());
  const DatumId s = rec.datum("s", kNoObject, sizeof e.s, &e.s);
  const KindId copy = rec.kind("copy"), scale = rec.kind("scale"), dot = rec.kind("dot");
  Cells* p = &e;
  for (int step = 0; step < 2; ++step) {
    rec.begin_step();
    // Correct: reads a, writes c.
    rec.task(copy, o, {{a, M::R}, {c, M::W}}, [p] { p->c = p->a; });
    // Wrong mode: writes b, declared R.
    rec.task(scale, o, {{b, M::R}, {c, M::RW}}, [p] {
      for (int i = 0; i < 4; ++i) p->b[i] *= 1.25, p->c[i] += p->b[i];
    });
    // Undeclared read: reads b, declares only c and s.
    rec.task(dot, o, {{c, M::R}, {s, M::W}}, [p] {
      p->s = 0;
      for (int i = 0; i < 4; ++i) p->s += p->c[i] * p->b[i];
    });
    rec.end_step();
  }
  const std::vector<AccessFinding> f = rec.access_findings();
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(to_string(f[0]), "task scale of tile(0,0) wrote b, declared R");
  EXPECT_EQ(to_string(f[1]), "task dot of tile(0,0) read b, declared none");
  EXPECT_EQ(f[1].found, AccessFound::kRead);
  // The state is what plain runs leave: check the last step's s against a recomputation.
  Cells ref;
  for (int step = 0; step < 2; ++step) {
    ref.c = ref.a;
    for (int i = 0; i < 4; ++i) ref.b[i] *= 1.25, ref.c[i] += ref.b[i];
    ref.s = 0;
    for (int i = 0; i < 4; ++i) ref.s += ref.c[i] * ref.b[i];
  }
  EXPECT_EQ(e.s, ref.s);
  EXPECT_EQ(e.b, ref.b);
  ASSERT_NE(rec.access_counts(), nullptr);
  EXPECT_EQ(rec.access_counts()->runs, 6u);
  EXPECT_GT(rec.access_counts()->reruns, 0u);
}

TEST(VerifyAccesses, CorrectDeclarationsFindNothingAndOffIsOff) {
  Cells e;
  Recorder rec(Mode::kCapture);
  const DatumId a = rec.datum("a", kNoObject, sizeof e.a, e.a.data());
  rec.set_verify_accesses(true);  // after declaring: the data known so far are checked
  const DatumId s = rec.datum("s", kNoObject, sizeof e.s, &e.s);
  const KindId sum = rec.kind("sum");
  Cells* p = &e;
  rec.begin_step();
  rec.task(sum, kNoObject, {{a, M::R}, {s, M::CW}}, [p] {
    for (double x : p->a) p->s += x;
  });
  rec.end_step();
  EXPECT_TRUE(rec.access_findings().empty());
  EXPECT_EQ(e.s, 12.0);  // once, although the read check ran the body again
  rec.set_verify_accesses(false);
  EXPECT_EQ(rec.access_counts(), nullptr);
}

TEST(VerifyAccesses, ABodyThatIsNotAFunctionOfItsStateIsNamed) {
  double x = 1, counter = 1;
  Recorder rec(Mode::kCapture);
  rec.set_verify_accesses(true);
  const DatumId d = rec.datum("x", kNoObject, sizeof x, &x);
  rec.datum("other", kNoObject, sizeof counter, &counter);
  const KindId k = rec.kind("tick");
  static double hidden = 0;  // state outside every datum
  rec.begin_step();
  rec.task(k, kNoObject, {{d, M::W}}, [&x] { x = ++hidden; });
  rec.end_step();
  const std::vector<AccessFinding> f = rec.access_findings();
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(to_string(f[0]), "task tick read (state outside the declared data), declared none");
}

TEST(VerifyAccesses, PerturbationIsItsOwnInverseAndSparesIntegersAndZeros) {
  std::array<double, 3> v{1.0, 0.0, -3.25e10};
  std::array<std::int64_t, 2> n{7, -1};
  const auto v0 = v;
  const auto n0 = n;
  AccessChecker::perturb(v.data(), sizeof v);
  AccessChecker::perturb(n.data(), sizeof n);
  EXPECT_NE(v[0], v0[0]);
  EXPECT_NEAR(v[0], 1.0, 1e-3);
  EXPECT_EQ(v[1], 0.0);
  EXPECT_NE(v[2], v0[2]);
  EXPECT_EQ(n, n0);
  AccessChecker::perturb(v.data(), sizeof v);
  EXPECT_EQ(v, v0);
}

}  // namespace
}  // namespace tgraph::capture
