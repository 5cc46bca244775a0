#include "core/planar/blocks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/planar/dynamics.hpp"

namespace bd::core::planar::detail {

namespace {

// a block whose rows meet at a sine below this (its determinant over its rows' norms), or whose
// pivots are further apart, is left to the general route, which decides whether the position is
// singular (dynamics.cpp: the same figure decides when the condition estimate is needed there)
constexpr double kWellConditioned = 1e-2;
// Newton's method on a general block: as the general route's (dynamics.cpp)
constexpr double kNewtonStep = 1e-14;
constexpr int kBlockIterations = 8;

const Vec2& at(const NodeVectors& x, int node) { return x[static_cast<std::size_t>(node)]; }

// the moving nodes' coordinates a row involves
std::vector<int> row_coordinates(const System& s, const NodeVectors& x, int row) {
  GradientEntry entries[3];
  const int count = row_gradient(s, x, row, entries);
  std::vector<int> out;
  for (int j = 0; j < count; ++j) {
    const int c = s.coord[static_cast<std::size_t>(entries[j].node)];
    if (c < 0 || std::find(out.begin(), out.end(), c) != out.end()) continue;
    out.push_back(c);
    out.push_back(c + 1);
  }
  return out;
}

// Kuhn's augmenting path from row r
bool augment(int r, const std::vector<std::vector<int>>& adjacent, std::vector<int>& row_of,
             std::vector<char>& seen) {
  for (int c : adjacent[static_cast<std::size_t>(r)]) {
    if (seen[static_cast<std::size_t>(c)]) continue;
    seen[static_cast<std::size_t>(c)] = 1;
    const int other = row_of[static_cast<std::size_t>(c)];
    if (other < 0 || augment(other, adjacent, row_of, seen)) {
      row_of[static_cast<std::size_t>(c)] = r;
      return true;
    }
  }
  return false;
}

// Tarjan's strongly connected components of the rows, row r depending on the row matched to
// each coordinate it involves; a component is emitted after every component it depends on
struct Components {
  const std::vector<std::vector<int>>& adjacent;
  const std::vector<int>& row_of;
  std::vector<int> index, low, stack;
  std::vector<char> on_stack;
  std::vector<std::vector<int>> out;
  int counter = 0;

  void visit(int r) {
    const std::size_t u = static_cast<std::size_t>(r);
    index[u] = low[u] = counter++;
    stack.push_back(r);
    on_stack[u] = 1;
    for (int c : adjacent[u]) {
      const int w = row_of[static_cast<std::size_t>(c)];
      const std::size_t v = static_cast<std::size_t>(w);
      if (index[v] < 0) {
        visit(w);
        low[u] = std::min(low[u], low[v]);
      } else if (on_stack[v]) {
        low[u] = std::min(low[u], index[v]);
      }
    }
    if (low[u] != index[u]) return;
    std::vector<int> component;
    int w = -1;
    do {
      w = stack.back();
      stack.pop_back();
      on_stack[static_cast<std::size_t>(w)] = 0;
      component.push_back(w);
    } while (w != r);
    std::sort(component.begin(), component.end());
    out.push_back(std::move(component));
  }
};

// the closed form of a block of two rows that place one node, if it has one
void classify(const System& s, const std::vector<int>& node_of, Block& b,
              const std::vector<int>& rows, const std::vector<int>& coords) {
  if (b.size != 2) return;
  const int c0 = coords[static_cast<std::size_t>(b.first)];
  const int c1 = coords[static_cast<std::size_t>(b.first) + 1];
  if (c1 != c0 + 1 || c0 % 2 != 0) return;
  const int P = node_of[static_cast<std::size_t>(c0)];
  using K = System::RowRef::Kind;
  const System::RowRef r0 =
      s.row_ref[static_cast<std::size_t>(rows[static_cast<std::size_t>(b.first)])];
  const System::RowRef r1 =
      s.row_ref[static_cast<std::size_t>(rows[static_cast<std::size_t>(b.first) + 1])];
  // the other end of element k from P, or -1
  auto other_end = [&](int k) {
    const System::ElementRow& e = s.elements[static_cast<std::size_t>(k)];
    return e.p == P ? e.q : e.q == P ? e.p : -1;
  };
  auto set = [&](Block::Kind kind, int a, int bb, double ra, double rb, int index) {
    b.kind = kind;
    b.node = P;
    b.a = a;
    b.b = bb;
    b.ra = ra;
    b.rb = rb;
    b.index = index;
  };
  if (r0.kind == K::kElement && r1.kind == K::kElement) {
    const int A = other_end(r0.index), B = other_end(r1.index);
    if (A < 0 || B < 0 || A == B) return;
    set(Block::Kind::kDyad, A, B, s.elements[static_cast<std::size_t>(r0.index)].length,
        s.elements[static_cast<std::size_t>(r1.index)].length, -1);
    return;
  }
  const System::RowRef* element = r0.kind == K::kElement   ? &r0
                                  : r1.kind == K::kElement ? &r1
                                                           : nullptr;
  const System::RowRef& other = element == &r0 ? r1 : r0;
  if (element != nullptr && other.kind == K::kInput) {
    const System::InputRow& in = s.inputs[static_cast<std::size_t>(other.index)];
    const System::ElementRow& e = s.elements[static_cast<std::size_t>(element->index)];
    if (!in.angle || in.p != e.p || in.q != e.q || other_end(element->index) < 0) return;
    // the input's angle is the direction p -> q
    set(Block::Kind::kCrank, other_end(element->index), -1, P == e.q ? e.length : -e.length, 0,
        in.input);
    return;
  }
  if (element != nullptr && other.kind == K::kSlider) {
    const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(other.index)];
    const int A = other_end(element->index);
    if (sl.on_link || sl.node != P || A < 0) return;
    set(Block::Kind::kGuide, A, -1, s.elements[static_cast<std::size_t>(element->index)].length, 0,
        other.index);
    return;
  }
  if (r0.kind == K::kSlider && r1.kind == K::kInput) {
    const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(r0.index)];
    const System::InputRow& in = s.inputs[static_cast<std::size_t>(r1.index)];
    if (sl.on_link || sl.node != P || in.angle || in.slider != r0.index) return;
    set(Block::Kind::kSlide, -1, -1, 0, 0, in.input);
    return;
  }
  if (r0.kind == K::kRigid && r1.kind == K::kRigid && r0.index == r1.index &&
      s.rigid[static_cast<std::size_t>(r0.index)].node == P) {
    set(Block::Kind::kRigid, -1, -1, 0, 0, r0.index);
  }
}

// the side of the line A -> B on which P lies (dyad), or of the foot of A on the guide (guide)
double side(const System& s, const Block& b, const NodeVectors& x) {
  const Vec2& P = at(x, b.node);
  const Vec2& A = at(x, b.a);
  if (b.kind == Block::Kind::kDyad) return cross(at(x, b.b) - A, P - A) < 0 ? -1.0 : 1.0;
  const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(b.index)];
  return sl.unit.dot(P - A) < 0 ? -1.0 : 1.0;
}

// the block's matrix, rows x coordinates, from the whole Jacobian
void block_matrix(const BlockPlan& plan, const Block& b, const Eigen::MatrixXd& G,
                  Eigen::MatrixXd& out) {
  out.resize(b.size, b.size);
  for (int i = 0; i < b.size; ++i) {
    for (int j = 0; j < b.size; ++j) {
      out(i, j) = G(plan.rows[static_cast<std::size_t>(b.first + i)],
                    plan.coords[static_cast<std::size_t>(b.first + j)]);
    }
  }
}

// a two-row block's determinant over its rows' norms: the sine at which they meet
double two_row_sine(double a, double b, double c, double d) {
  const double n = std::sqrt((a * a + b * b) * (c * c + d * d));
  return n > 0 ? (a * d - b * c) / n : 0.0;
}

// the sign of a permutation of 0..n-1 (by its cycles)
double permutation_sign(const std::vector<int>& order) {
  std::vector<char> seen(order.size(), 0);
  double sign = 1;
  for (std::size_t i = 0; i < order.size(); ++i) {
    std::size_t length = 0;
    for (std::size_t j = i; !seen[j]; j = static_cast<std::size_t>(order[j])) {
      seen[j] = 1;
      ++length;
    }
    if (length > 0 && length % 2 == 0) sign = -sign;
  }
  return sign;
}

}  // namespace

BlockPlan plan_blocks(const System& s) {
  BlockPlan plan;
  if (s.rows != s.n || s.n == 0) return plan;
  NodeVectors x;
  for (const Node& n : s.linkage.nodes) x.push_back(n.position);
  std::vector<std::vector<int>> adjacent(static_cast<std::size_t>(s.rows));
  for (int r = 0; r < s.rows; ++r) adjacent[static_cast<std::size_t>(r)] = row_coordinates(s, x, r);
  std::vector<int> row_of(static_cast<std::size_t>(s.n), -1);
  for (int r = 0; r < s.rows; ++r) {
    std::vector<char> seen(static_cast<std::size_t>(s.n), 0);
    if (!augment(r, adjacent, row_of, seen)) return plan;
  }
  std::vector<int> coord_of(static_cast<std::size_t>(s.rows), -1);
  for (int c = 0; c < s.n; ++c)
    coord_of[static_cast<std::size_t>(row_of[static_cast<std::size_t>(c)])] = c;
  Components tarjan{adjacent, row_of, {}, {}, {}, {}, {}, 0};
  tarjan.index.assign(static_cast<std::size_t>(s.rows), -1);
  tarjan.low.assign(static_cast<std::size_t>(s.rows), -1);
  tarjan.on_stack.assign(static_cast<std::size_t>(s.rows), 0);
  for (int r = 0; r < s.rows; ++r) {
    if (tarjan.index[static_cast<std::size_t>(r)] < 0) tarjan.visit(r);
  }
  std::vector<int> node_of(static_cast<std::size_t>(s.n), -1);
  for (int i : s.moving) {
    node_of[static_cast<std::size_t>(s.coord[static_cast<std::size_t>(i)])] = i;
    node_of[static_cast<std::size_t>(s.coord[static_cast<std::size_t>(i)]) + 1] = i;
  }
  plan.closed = true;
  for (const std::vector<int>& component : tarjan.out) {
    Block b;
    b.first = static_cast<int>(plan.rows.size());
    b.size = static_cast<int>(component.size());
    std::vector<int> coords;
    for (int r : component) coords.push_back(coord_of[static_cast<std::size_t>(r)]);
    std::sort(coords.begin(), coords.end());
    plan.rows.insert(plan.rows.end(), component.begin(), component.end());
    plan.coords.insert(plan.coords.end(), coords.begin(), coords.end());
    classify(s, node_of, b, plan.rows, plan.coords);
    plan.closed = plan.closed && b.kind != Block::Kind::kGeneral;
    plan.blocks.push_back(b);
  }
  // the substitutions' terms: the entries of the rows outside the diagonal blocks
  std::vector<int> block_of_row(static_cast<std::size_t>(s.rows)), block_of_coord(block_of_row);
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& b = plan.blocks[k];
    for (int i = b.first; i < b.first + b.size; ++i) {
      block_of_row[static_cast<std::size_t>(plan.rows[static_cast<std::size_t>(i)])] =
          static_cast<int>(k);
      block_of_coord[static_cast<std::size_t>(plan.coords[static_cast<std::size_t>(i)])] =
          static_cast<int>(k);
    }
  }
  auto offset = [&s](int r, int c) { return r + c * s.rows; };
  for (int r : plan.rows) {
    plan.row_first.push_back(static_cast<int>(plan.row_terms.size()));
    for (int c : adjacent[static_cast<std::size_t>(r)]) {
      if (block_of_coord[static_cast<std::size_t>(c)] < block_of_row[static_cast<std::size_t>(r)])
        plan.row_terms.push_back({offset(r, c), c});
    }
  }
  plan.row_first.push_back(static_cast<int>(plan.row_terms.size()));
  for (int c : plan.coords) {
    plan.coord_first.push_back(static_cast<int>(plan.coord_terms.size()));
    for (int r = 0; r < s.rows; ++r) {
      const std::vector<int>& a = adjacent[static_cast<std::size_t>(r)];
      if (block_of_row[static_cast<std::size_t>(r)] > block_of_coord[static_cast<std::size_t>(c)] &&
          std::find(a.begin(), a.end(), c) != a.end())
        plan.coord_terms.push_back({offset(r, c), r});
    }
  }
  plan.coord_first.push_back(static_cast<int>(plan.coord_terms.size()));
  for (Block& b : plan.blocks) {
    if (b.size != 2) continue;
    const int* r = &plan.rows[static_cast<std::size_t>(b.first)];
    const int* c = &plan.coords[static_cast<std::size_t>(b.first)];
    b.entry[0] = offset(r[0], c[0]);
    b.entry[1] = offset(r[0], c[1]);
    b.entry[2] = offset(r[1], c[0]);
    b.entry[3] = offset(r[1], c[1]);
  }
  plan.permutation_sign = permutation_sign(plan.rows) * permutation_sign(plan.coords);
  plan.usable = true;
  return plan;
}

void prime_blocks(const Model& model, Workspace& ws) {
  const System& s = model.system();
  const BlockPlan& plan = s.blocks;
  ws.block_sign.assign(plan.blocks.size(), 1.0);
  ws.block_lu.resize(plan.blocks.size());
  ws.block_det.assign(plan.blocks.size(), 0.0);
  ws.block_margin.assign(plan.blocks.size(), 0.0);
  if (!plan.usable) return;
  bool general = false;
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& b = plan.blocks[k];
    if (b.kind == Block::Kind::kDyad || b.kind == Block::Kind::kGuide) {
      ws.block_sign[k] = side(s, b, ws.instant.x);
    } else if (b.kind == Block::Kind::kGeneral) {
      general = true;
    }
  }
  if (!general) return;
  constraint_jacobian(s, ws.instant.x, s.rows, ws.G);
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& b = plan.blocks[k];
    if (b.kind != Block::Kind::kGeneral) continue;
    block_matrix(plan, b, ws.G, ws.block_matrix);
    ws.block_lu[k].compute(ws.block_matrix);
    ws.block_sign[k] = ws.block_lu[k].determinant() < 0 ? -1.0 : 1.0;
  }
}

bool prime_closed_blocks(const Model& model, Workspace& ws, const NodeVectors& x) {
  const System& s = model.system();
  const BlockPlan& plan = s.blocks;
  if (!plan.usable || !plan.closed) return false;
  ws.block_sign.resize(plan.blocks.size());
  ws.block_det.resize(plan.blocks.size());
  ws.block_margin.resize(plan.blocks.size());
  ws.block_lu.resize(plan.blocks.size());
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& b = plan.blocks[k];
    double measure = 0, scale = 0;  // the branch's sign and its size over the legs'
    if (b.kind == Block::Kind::kDyad) {
      const Vec2 d = at(x, b.b) - at(x, b.a), e = at(x, b.node) - at(x, b.a);
      measure = cross(d, e);
      scale = d.norm() * e.norm();
    } else if (b.kind == Block::Kind::kGuide) {
      const Vec2 e = at(x, b.node) - at(x, b.a);
      measure = s.sliders[static_cast<std::size_t>(b.index)].unit.dot(e);
      scale = e.norm();
    } else {  // (a crank, a slide, a further node: one position, no branch)
      ws.block_sign[k] = 1.0;
      continue;
    }
    if (!(std::abs(measure) >= kWellConditioned * scale) || !(scale > 0)) return false;
    ws.block_sign[k] = measure < 0 ? -1.0 : 1.0;
  }
  return true;
}

Placement place_by_blocks(const Model& model, Workspace& ws, const NodeVectors& guess,
                          const std::vector<double>& inputs) {
  const System& s = model.system();
  const BlockPlan& plan = s.blocks;
  if (!plan.usable || ws.block_sign.size() != plan.blocks.size()) return Placement::kDeclined;
  Instant& in = ws.instant;
  input_targets(s, inputs, ws.target);
  NodeVectors& x = in.x;
  if (!plan.closed) x = guess;
  const double step_limit = kNewtonStep * model.length_scale();
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& b = plan.blocks[k];
    const std::size_t P = static_cast<std::size_t>(b.node);
    switch (b.kind) {
      case Block::Kind::kCrank:
        x[P] = at(x, b.a) + b.ra * ws.target[static_cast<std::size_t>(b.index)];
        break;
      case Block::Kind::kDyad: {
        // P on the circles |P - A| = ra and |P - B| = rb: a along A -> B, h across it
        const Vec2& A = at(x, b.a);
        const Vec2 d = at(x, b.b) - A;
        const double D = d.norm();
        const double along = (b.ra * b.ra - b.rb * b.rb + D * D) / (2 * D);
        const double h2 = (b.ra - along) * (b.ra + along);
        ws.block_margin[k] = h2;  // (below 0 too: how far it is from closing)
        if (!(h2 >= 0) || !(D > 0)) return Placement::kDeclined;
        x[P] = A + (along / D) * d + (ws.block_sign[k] * std::sqrt(h2) / D) * perp(d);
        break;
      }
      case Block::Kind::kGuide: {
        // P on the guide from + s u at |P - A| = ra: s from the foot of A on the guide
        const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(b.index)];
        const Vec2 w = at(x, b.a) - sl.from;
        const double off = sl.normal.dot(w);
        const double h2 = (b.ra - off) * (b.ra + off);
        ws.block_margin[k] = h2;
        if (!(h2 >= 0)) return Placement::kDeclined;
        x[P] = sl.from + (sl.unit.dot(w) + ws.block_sign[k] * std::sqrt(h2)) * sl.unit;
        break;
      }
      case Block::Kind::kSlide: {
        const System::InputRow& ir = s.inputs[static_cast<std::size_t>(b.index)];
        const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(ir.slider)];
        x[P] = sl.from + inputs[static_cast<std::size_t>(b.index)] * sl.unit;
        break;
      }
      case Block::Kind::kRigid: {
        const System::RigidRows& r = s.rigid[static_cast<std::size_t>(b.index)];
        x[P] = r.weights.at_p * at(x, r.p) + r.weights.at_q * at(x, r.q);
        break;
      }
      case Block::Kind::kGeneral: {
        // Newton's method on the block's rows, the blocks before it fixed
        bool converged = false;
        for (int it = 0; it < kBlockIterations && !converged; ++it) {
          constraint_values(s, x, ws.target, ws.g);
          constraint_jacobian(s, x, s.rows, ws.G);
          block_matrix(plan, b, ws.G, ws.block_matrix);
          SmallLu& lu = ws.block_lu[k];
          lu.compute(ws.block_matrix);
          if (!(lu.pivot_ratio() >= kWellConditioned)) return Placement::kDeclined;
          ws.block_rhs.resize(b.size);
          for (int i = 0; i < b.size; ++i)
            ws.block_rhs[i] = ws.g[plan.rows[static_cast<std::size_t>(b.first + i)]];
          lu.solve(ws.block_rhs, ws.block_x);
          if (!ws.block_x.allFinite()) return Placement::kDeclined;
          for (int j = 0; j < b.size; ++j) {
            const int c = plan.coords[static_cast<std::size_t>(b.first + j)];
            Vec2& node = x[static_cast<std::size_t>(s.moving[static_cast<std::size_t>(c / 2)])];
            node[c % 2] -= ws.block_x[j];
          }
          converged = ws.block_x.cwiseAbs().maxCoeff() <= step_limit;
        }
        if (!converged) return Placement::kDeclined;
        break;
      }
    }
  }
  // the Jacobian at the solution and the blocks' factorisations
  // (a value that is not finite fails the blocks' conditioning tests, or the finish's check of
  // the multipliers)
  constraint_jacobian(s, x, s.rows, ws.G);
  const double* G = ws.G.data();
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& b = plan.blocks[k];
    if (b.size == 2) {
      const double g00 = G[b.entry[0]], g01 = G[b.entry[1]], g10 = G[b.entry[2]],
                   g11 = G[b.entry[3]];
      if (!(std::abs(two_row_sine(g00, g01, g10, g11)) >= kWellConditioned)) {
        // every node is placed, on the recorded branches where the blocks are closed forms
        return plan.closed ? Placement::kIllConditioned : Placement::kDeclined;
      }
      ws.block_det[k] = g00 * g11 - g01 * g10;
      if (b.kind == Block::Kind::kGeneral && (ws.block_det[k] < 0 ? -1.0 : 1.0) != ws.block_sign[k])
        return Placement::kDeclined;
    } else {
      block_matrix(plan, b, ws.G, ws.block_matrix);
      SmallLu& lu = ws.block_lu[k];
      lu.compute(ws.block_matrix);
      if (!(lu.pivot_ratio() >= kWellConditioned) ||
          (lu.determinant() < 0 ? -1.0 : 1.0) != ws.block_sign[k])
        return Placement::kDeclined;
    }
  }
  if (in.input.size() == inputs.size()) {
    std::copy(inputs.begin(), inputs.end(), in.input.begin());
  } else {
    in.input = inputs;
  }
  ws.factorised = false;  // ws.lu is not at this position
  ws.by_blocks = true;
  return Placement::kPlaced;
}

double block_determinant(const Model& model, const Workspace& ws) {
  const BlockPlan& plan = model.system().blocks;
  double d = plan.permutation_sign;
  for (std::size_t k = 0; k < plan.blocks.size(); ++k)
    d *= plan.blocks[k].size == 2 ? ws.block_det[k] : ws.block_lu[k].determinant();
  return d;
}

void block_solve(const Model& model, Workspace& ws, const Eigen::VectorXd& rhs,
                 Eigen::VectorXd& x) {
  const BlockPlan& plan = model.system().blocks;
  const double* G = ws.G.data();
  const double* b = rhs.data();
  x.resize(ws.G.cols());
  double* out = x.data();
  const int* first = plan.row_first.data();
  const BlockPlan::Term* terms = plan.row_terms.data();
  // the right-hand side of row entry i less its terms in the coordinates already solved
  auto reduced = [&](int i) {
    double y = b[plan.rows[static_cast<std::size_t>(i)]];
    for (int j = first[i]; j < first[i + 1]; ++j) y -= G[terms[j].entry] * out[terms[j].other];
    return y;
  };
  for (std::size_t k = 0; k < plan.blocks.size(); ++k) {
    const Block& bl = plan.blocks[k];
    const int* c = &plan.coords[static_cast<std::size_t>(bl.first)];
    if (bl.size == 2) {
      const double y0 = reduced(bl.first), y1 = reduced(bl.first + 1);
      const double det = ws.block_det[k];
      out[c[0]] = (G[bl.entry[3]] * y0 - G[bl.entry[1]] * y1) / det;
      out[c[1]] = (G[bl.entry[0]] * y1 - G[bl.entry[2]] * y0) / det;
    } else {
      ws.block_rhs.resize(bl.size);
      for (int i = 0; i < bl.size; ++i) ws.block_rhs[i] = reduced(bl.first + i);
      ws.block_lu[k].solve(ws.block_rhs, ws.block_x);
      for (int j = 0; j < bl.size; ++j) out[c[j]] = ws.block_x[j];
    }
  }
}

void block_solve_transpose(const Model& model, Workspace& ws, const Eigen::VectorXd& b,
                           Eigen::VectorXd& x) {
  const BlockPlan& plan = model.system().blocks;
  const double* G = ws.G.data();
  const double* in = b.data();
  x.resize(ws.G.rows());
  double* out = x.data();
  const int* first = plan.coord_first.data();
  const BlockPlan::Term* terms = plan.coord_terms.data();
  // the right-hand side of coordinate entry j less its terms in the rows already solved
  auto reduced = [&](int j) {
    double y = in[plan.coords[static_cast<std::size_t>(j)]];
    for (int i = first[j]; i < first[j + 1]; ++i) y -= G[terms[i].entry] * out[terms[i].other];
    return y;
  };
  for (std::size_t k = plan.blocks.size(); k-- > 0;) {
    const Block& bl = plan.blocks[k];
    const int* r = &plan.rows[static_cast<std::size_t>(bl.first)];
    if (bl.size == 2) {
      const double y0 = reduced(bl.first), y1 = reduced(bl.first + 1);
      const double det = ws.block_det[k];
      out[r[0]] = (G[bl.entry[3]] * y0 - G[bl.entry[2]] * y1) / det;
      out[r[1]] = (G[bl.entry[0]] * y1 - G[bl.entry[1]] * y0) / det;
    } else {
      ws.block_rhs.resize(bl.size);
      for (int j = 0; j < bl.size; ++j) ws.block_rhs[j] = reduced(bl.first + j);
      ws.block_lu[k].solve_transpose(ws.block_rhs);
      for (int i = 0; i < bl.size; ++i) out[r[i]] = ws.block_rhs[i];
    }
  }
}

void closed_form_kinematics(const Model& model, Workspace& ws, const std::vector<double>& rates,
                            const std::vector<double>& accelerations) {
  const System& s = model.system();
  const BlockPlan& plan = s.blocks;
  Instant& in = ws.instant;
  const NodeVectors& x = in.x;
  NodeVectors& v = in.v;
  NodeVectors& a = in.a;
  for (int i : s.fixed) {
    v[static_cast<std::size_t>(i)] = Vec2(0, 0);
    a[static_cast<std::size_t>(i)] = Vec2(0, 0);
  }
  for (const Block& b : plan.blocks) {
    const std::size_t P = static_cast<std::size_t>(b.node);
    switch (b.kind) {
      case Block::Kind::kCrank: {
        // P = A + L u(θ): v = v_A + L θ̇ perp(u), a = a_A + L (θ̈ perp(u) - θ̇² u)
        const std::size_t k = static_cast<std::size_t>(b.index);
        const Vec2& u = ws.target[k];
        const double w = rates[k], dw = accelerations[k];
        v[P] = at(v, b.a) + (b.ra * w) * perp(u);
        a[P] = at(a, b.a) + b.ra * (dw * perp(u) - (w * w) * u);
        break;
      }
      case Block::Kind::kDyad: {
        // (P - A)·(v_P - v_A) = 0, (P - B)·(v_P - v_B) = 0; differentiated once more,
        // (P - A)·(a_P - a_A) = -|v_P - v_A|², likewise for B
        const Vec2 ea = x[P] - at(x, b.a), eb = x[P] - at(x, b.b);
        const double det = cross(ea, eb);
        auto solve = [&](double y0, double y1) {
          return Vec2((y0 * eb.y() - y1 * ea.y()) / det, (ea.x() * y1 - eb.x() * y0) / det);
        };
        v[P] = solve(ea.dot(at(v, b.a)), eb.dot(at(v, b.b)));
        const Vec2 wa = v[P] - at(v, b.a), wb = v[P] - at(v, b.b);
        a[P] = solve(ea.dot(at(a, b.a)) - wa.squaredNorm(), eb.dot(at(a, b.b)) - wb.squaredNorm());
        break;
      }
      case Block::Kind::kGuide: {
        // P moves along the guide: (P - A)·(ṡ u - v_A) = 0, (P - A)·(s̈ u - a_A) = -|v_P - v_A|²
        const System::SliderRow& sl = s.sliders[static_cast<std::size_t>(b.index)];
        const Vec2 ea = x[P] - at(x, b.a);
        const double along = ea.dot(sl.unit);
        v[P] = (ea.dot(at(v, b.a)) / along) * sl.unit;
        const Vec2 wa = v[P] - at(v, b.a);
        a[P] = ((ea.dot(at(a, b.a)) - wa.squaredNorm()) / along) * sl.unit;
        break;
      }
      case Block::Kind::kSlide: {
        const System::InputRow& ir = s.inputs[static_cast<std::size_t>(b.index)];
        const Vec2& unit = s.sliders[static_cast<std::size_t>(ir.slider)].unit;
        v[P] = rates[static_cast<std::size_t>(b.index)] * unit;
        a[P] = accelerations[static_cast<std::size_t>(b.index)] * unit;
        break;
      }
      case Block::Kind::kRigid: {
        const System::RigidRows& r = s.rigid[static_cast<std::size_t>(b.index)];
        v[P] = r.weights.at_p * at(v, r.p) + r.weights.at_q * at(v, r.q);
        a[P] = r.weights.at_p * at(a, r.p) + r.weights.at_q * at(a, r.q);
        break;
      }
      case Block::Kind::kGeneral:
        break;  // (not a closed plan)
    }
  }
  std::copy(rates.begin(), rates.end(), in.input_rate.begin());
  std::copy(accelerations.begin(), accelerations.end(), in.input_acceleration.begin());
}

}  // namespace bd::core::planar::detail
