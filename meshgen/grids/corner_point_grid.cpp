#include "corner_point_grid.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace hm {

namespace {

// A pillar pair (the two pillars a column face lies on) seen as the strip s in [0, 1] (s = 0 on its
// first pillar) x depth z. Every cell face on it is the band between the cell's top line and its
// bottom line, each line the straight edge between the cell's corner depths on the two pillars,
// identified by those two exact ZCORN values. Two lines of the two sides of a fault that cross
// inside the strip (their order on the two pillars is opposite) meet at a crossing node, placed
// where the two straight edges reach the same depth; every node lying on a line (its two pillar
// ends and its crossings) is a station of it, and every face edge along the line names all the
// stations it passes (no hanging node).
constexpr double kPiValue = 3.14159265358979323846;
constexpr int kAbove = -1;  // the line z = -infinity (a gap band above a column's first cell)
constexpr int kBelow = -2;  // z = +infinity

struct Station {
  double s;
  int32_t node;
};

struct PillarPair {
  int pillar[2];
  std::vector<std::array<double, 2>> lines;  // depth on pillar[0], pillar[1]
  std::map<std::array<double, 2>, int> line_of;
  std::vector<std::vector<Station>> stations;  // per line, in increasing s
  std::map<std::pair<int, int>, Station> crossing;
};

int sgn(double a, double b) { return (a > b) - (a < b); }

// The pillar of corner q of cell c.
int cell_corner_pillar(const CornerPointModel& m, int c, int q) {
  const int i = c % m.nx + (q & 1), j = (c / m.nx) % m.ny + ((q >> 1) & 1);
  return i + (m.nx + 1) * j;
}

struct Band {
  int top, bottom;  // line ids (or kAbove / kBelow)
};

class CornerPointMesher {
 public:
  CornerPointMesher(const CornerPointModel& m, const std::vector<char>& active, MeshBuilder& b) : m_(m), b_(b) {
    const int n = m.nx * m.ny * m.nz;
    meshed_.assign(n, 0);
    for (int c = 0; c < n; ++c) {
      if (!m.actnum[c] || !active[c]) continue;
      bool thick = false;
      for (int q = 0; q < 4; ++q) thick = thick || corner_depth(m, c, q) != corner_depth(m, c, q + 4);
      if (thick) meshed_[c] = 1;
      else ++zero_volume_;
    }
    make_pillar_nodes();
    make_pairs();
  }

  // Every meshed cell's faces (outward), each with the model cell across it (-1: none).
  CornerPointCellFaces cell_faces(int32_t boundary_patch) {
    const int n = m_.nx * m_.ny * m_.nz;
    staged_ = {};
    groups_.clear();
    for (size_t p = 0; p < pairs_.size(); ++p) pair_faces(static_cast<int>(p), boundary_patch);
    for (int c = 0; c < n; ++c)
      if (meshed_[c]) top_bottom_faces(c, boundary_patch);
    CornerPointCellFaces out = by_cell(n);
    if (left_handed()) {
      for (size_t f = 0; f + 1 < out.node_start.size(); ++f)
        std::reverse(out.nodes.begin() + out.node_start[f], out.nodes.begin() + out.node_start[f + 1]);
      for (auto& g : groups_) std::reverse(g.begin(), g.end());
    }
    out.groups = std::move(groups_);
    out.meshed = meshed_;
    out.zero_volume_cells = zero_volume_;
    out.fault_faces = fault_faces_;
    out.crossing_nodes = crossings_;
    return out;
  }

 private:
  // The faces in the order they are made (pillar pairs, then tops and bottoms), each with its cell.
  struct Staged {
    std::vector<int32_t> cell, patch, neighbour, group;
    std::vector<int64_t> node_start{0};
    std::vector<int32_t> nodes;
  };
  void stage(int32_t c, const int32_t* v, size_t count, int32_t patch, int32_t across, int32_t group) {
    staged_.cell.push_back(c);
    staged_.patch.push_back(patch);
    staged_.neighbour.push_back(across);
    staged_.group.push_back(group);
    staged_.nodes.insert(staged_.nodes.end(), v, v + count);
    staged_.node_start.push_back(static_cast<int64_t>(staged_.nodes.size()));
  }
  // The staged faces grouped by cell, each cell's in the order they were made (a stable counting sort).
  CornerPointCellFaces by_cell(int n) {
    CornerPointCellFaces out;
    const size_t nf = staged_.cell.size();
    out.cell_start.assign(static_cast<size_t>(n) + 1, 0);
    for (int32_t c : staged_.cell) ++out.cell_start[c + 1];
    for (int c = 0; c < n; ++c) out.cell_start[c + 1] += out.cell_start[c];
    std::vector<int64_t> slot(nf), next(out.cell_start.begin(), out.cell_start.end() - 1);
    for (size_t f = 0; f < nf; ++f) slot[f] = next[staged_.cell[f]]++;
    out.patch.resize(nf), out.neighbour.resize(nf), out.group.resize(nf);
    out.node_start.assign(nf + 1, 0);  // face sizes, then their running sums
    for (size_t f = 0; f < nf; ++f) {
      out.patch[slot[f]] = staged_.patch[f];
      out.neighbour[slot[f]] = staged_.neighbour[f];
      out.group[slot[f]] = staged_.group[f];
      out.node_start[slot[f] + 1] = staged_.node_start[f + 1] - staged_.node_start[f];
    }
    for (size_t f = 0; f < nf; ++f) out.node_start[f + 1] += out.node_start[f];
    out.nodes.resize(staged_.nodes.size());
    for (size_t f = 0; f < nf; ++f)
      std::copy(staged_.nodes.begin() + staged_.node_start[f], staged_.nodes.begin() + staged_.node_start[f + 1],
                out.nodes.begin() + out.node_start[slot[f]]);
    staged_ = {};
    return out;
  }

  const CornerPointModel& m_;
  MeshBuilder& b_;
  Staged staged_;
  std::vector<char> meshed_;
  int64_t zero_volume_ = 0, fault_faces_ = 0, crossings_ = 0;
  std::vector<std::vector<double>> pillar_depth_;
  std::vector<std::vector<int32_t>> pillar_node_;
  std::vector<PillarPair> pairs_;
  std::vector<std::vector<int32_t>> groups_;  // the cycle each split group fans
  std::map<std::array<int32_t, 4>, int32_t> face_centre_;
  std::vector<Band> band_;  // per cell and side (4 c + side): its top and bottom line on that pillar pair  // centre node of a split top/bottom face, by its corners

  // The face cycles above are outward when (i, j, depth) is a right-handed frame, i.e. when the
  // columns turn counter-clockwise in plan from +i to +j (x east, y north with j). Many models number
  // j the other way (southward): the sign of their summed plan area (the pillars' top points,
  // shoelace) says so, and every cycle is reversed.
  bool left_handed() const {
    double area = 0;
    for (int j = 0; j < m_.ny; ++j)
      for (int i = 0; i < m_.nx; ++i) {
        const int p[4] = {i + (m_.nx + 1) * j, i + 1 + (m_.nx + 1) * j, i + 1 + (m_.nx + 1) * (j + 1), i + (m_.nx + 1) * (j + 1)};
        for (int e = 0; e < 4; ++e) {
          const double* a = &m_.coord[6 * size_t(p[e])];
          const double* b = &m_.coord[6 * size_t(p[(e + 1) % 4])];
          area += a[0] * b[1] - a[1] * b[0];
        }
      }
    return area < 0;
  }

  int pillar_of(int c, int q) const { return cell_corner_pillar(m_, c, q); }
  Vec3 corner_point(int c, int q) const { return pillar_point(m_, pillar_of(c, q), corner_depth(m_, c, q)); }

  void make_pillar_nodes() {
    const int np = (m_.nx + 1) * (m_.ny + 1);
    pillar_depth_.assign(np, {});
    pillar_node_.assign(np, {});
    for (int c = 0; c < static_cast<int>(meshed_.size()); ++c)
      if (meshed_[c])
        for (int q = 0; q < 8; ++q) pillar_depth_[pillar_of(c, q)].push_back(corner_depth(m_, c, q));
    for (int p = 0; p < np; ++p) {
      auto& d = pillar_depth_[p];
      std::sort(d.begin(), d.end());
      d.erase(std::unique(d.begin(), d.end()), d.end());
      for (double z : d) pillar_node_[p].push_back(b_.add_node(pillar_point(m_, p, z)));
    }
  }
  int32_t pillar_node(int p, double z) const {
    const auto& d = pillar_depth_[p];
    return pillar_node_[p][std::lower_bound(d.begin(), d.end(), z) - d.begin()];
  }

  // Pair ids: i-pairs (the plane between columns i-1 and i, pillars (I, j) and (I, j+1)) first, then
  // j-pairs (pillars (i, J) and (i+1, J)).
  int n_ipairs() const { return (m_.nx + 1) * m_.ny; }
  int ipair(int I, int j) const { return I + (m_.nx + 1) * j; }
  int jpair(int i, int J) const { return n_ipairs() + i + m_.nx * J; }
  // Side 0 -i, 1 +i, 2 -j, 3 +j of cell c: its pair, and the corners (s = 0, s = 1) of its top edge
  // there (the bottom edge: the same + 4).
  int side_pair(int c, int side) const {
    const int i = c % m_.nx, j = (c / m_.nx) % m_.ny;
    switch (side) {
      case 0: return ipair(i, j);
      case 1: return ipair(i + 1, j);
      case 2: return jpair(i, j);
      default: return jpair(i, j + 1);
    }
  }
  static std::array<int, 2> side_corners(int side) {
    static const int kCorners[4][2] = {{0, 2}, {1, 3}, {0, 1}, {2, 3}};
    return {kCorners[side][0], kCorners[side][1]};
  }
  int line_id(int c, int side, bool bottom) const {
    const Band& b = band_[4 * size_t(c) + side];
    return bottom ? b.bottom : b.top;
  }
  int find_line_id(int c, int side, bool bottom) const {
    const auto q = side_corners(side);
    const int off = bottom ? 4 : 0;
    const PillarPair& pp = pairs_[side_pair(c, side)];
    return pp.line_of.at({corner_depth(m_, c, q[0] + off), corner_depth(m_, c, q[1] + off)});
  }

  void make_pairs() {
    const int nx = m_.nx, ny = m_.ny;
    pairs_.resize(n_ipairs() + nx * (ny + 1));
    for (int j = 0; j < ny; ++j)
      for (int I = 0; I <= nx; ++I) pairs_[ipair(I, j)].pillar[0] = I + (nx + 1) * j, pairs_[ipair(I, j)].pillar[1] = I + (nx + 1) * (j + 1);
    for (int J = 0; J <= ny; ++J)
      for (int i = 0; i < nx; ++i) pairs_[jpair(i, J)].pillar[0] = i + (nx + 1) * J, pairs_[jpair(i, J)].pillar[1] = i + 1 + (nx + 1) * J;
    for (int c = 0; c < static_cast<int>(meshed_.size()); ++c) {
      if (!meshed_[c]) continue;
      for (int side = 0; side < 4; ++side) {
        PillarPair& pp = pairs_[side_pair(c, side)];
        const auto q = side_corners(side);
        for (int off : {0, 4}) {
          const std::array<double, 2> l{corner_depth(m_, c, q[0] + off), corner_depth(m_, c, q[1] + off)};
          if (pp.line_of.emplace(l, static_cast<int>(pp.lines.size())).second) pp.lines.push_back(l);
        }
      }
    }
    for (PillarPair& pp : pairs_) make_stations(pp);
    band_.assign(4 * meshed_.size(), Band{kAbove, kBelow});
    for (int c = 0; c < static_cast<int>(meshed_.size()); ++c)
      if (meshed_[c])
        for (int side = 0; side < 4; ++side) band_[4 * size_t(c) + side] = {find_line_id(c, side, false), find_line_id(c, side, true)};
  }

  // Crossings: two lines whose order on the two pillars is strictly opposite (exact comparisons of
  // their ZCORN values) cross inside the strip. Only lines of the two different sides can: in a
  // column the lines are ordered on both pillars (check_corner_point_geometry).
  void make_stations(PillarPair& pp) {
    const int nl = static_cast<int>(pp.lines.size());
    pp.stations.assign(nl, {});
    for (int a = 0; a < nl; ++a)
      for (int b = a + 1; b < nl; ++b) {
        const auto& la = pp.lines[a];
        const auto& lb = pp.lines[b];
        if (sgn(la[0], lb[0]) * sgn(la[1], lb[1]) >= 0) continue;
        const double d0 = la[0] - lb[0], d1 = la[1] - lb[1];
        const double s = d0 / (d0 - d1);
        // Each line is the straight edge between its two corners; where the pillars are not parallel
        // the two edges pass at one depth at s a little apart: the node is their midpoint there.
        auto edge = [&](const std::array<double, 2>& l) {
          return (1 - s) * pillar_point(m_, pp.pillar[0], l[0]) + s * pillar_point(m_, pp.pillar[1], l[1]);
        };
        const Vec3 p = 0.5 * (edge(la) + edge(lb));
        const Station st{s, b_.add_node(p)};
        ++crossings_;
        pp.crossing[{a, b}] = st;
        pp.stations[a].push_back(st);
        pp.stations[b].push_back(st);
      }
    for (int l = 0; l < nl; ++l) {
      auto& st = pp.stations[l];
      std::sort(st.begin(), st.end(), [](const Station& x, const Station& y) { return x.s < y.s || (x.s == y.s && x.node < y.node); });
      st.insert(st.begin(), Station{0.0, pillar_node(pp.pillar[0], pp.lines[l][0])});
      st.push_back(Station{1.0, pillar_node(pp.pillar[1], pp.lines[l][1])});
    }
  }

  static double depth(const PillarPair& pp, int line, int end) {
    if (line == kAbove) return -std::numeric_limits<double>::infinity();
    if (line == kBelow) return std::numeric_limits<double>::infinity();
    return pp.lines[line][end];
  }
  static const Station& crossing(const PillarPair& pp, int a, int b) {
    return pp.crossing.at({std::min(a, b), std::max(a, b)});
  }
  // Appends the stations of `line` after node `from` up to node `to` (included).
  static void along(const PillarPair& pp, int line, int32_t from, int32_t to, std::vector<int32_t>& out) {
    const auto& st = pp.stations[line];
    int a = -1, b = -1;
    for (int k = 0; k < static_cast<int>(st.size()); ++k) {
      if (st[k].node == from) a = k;
      if (st[k].node == to) b = k;
    }
    if (a < 0 || b < 0) throw std::logic_error("corner-point grid: a face vertex is not a station of its edge");
    const int step = b > a ? 1 : -1;
    for (int k = a + step; k != b + step; k += step) out.push_back(st[k].node);
  }
  // Appends the pillar nodes after depth z_from up to depth z_to (included).
  void along_pillar(int p, double z_from, double z_to, std::vector<int32_t>& out) const {
    const auto& d = pillar_depth_[p];
    int a = static_cast<int>(std::lower_bound(d.begin(), d.end(), z_from) - d.begin());
    int b = static_cast<int>(std::lower_bound(d.begin(), d.end(), z_to) - d.begin());
    const int step = b > a ? 1 : -1;
    if (a == b) return;
    for (int k = a + step; k != b + step; k += step) out.push_back(pillar_node_[p][k]);
  }

  // The part of the strip in both bands, {max(tops) <= z <= min(bottoms)}: a convex polygon whose
  // vertex cycle runs along its upper boundary in increasing s, down the s = 1 pillar, back along
  // its lower boundary and up the s = 0 pillar (outward for the i-pair's -i column and the j-pair's
  // +j column). Empty when the bands share no area. The decisions (empty, which line bounds where)
  // are exact comparisons of ZCORN values; only two crossing positions are compared numerically
  // (a band ending at two crossings, a throw changing sign between the pillars).
  std::vector<int32_t> band_polygon(const PillarPair& pp, Band x, Band y) const {
    std::vector<int32_t> out;
    if (x.top == x.bottom || y.top == y.bottom) return out;
    struct Limit {  // bottom of one band minus the top of the other
      int top, bottom, s0, s1;
    };
    const Limit lim[2] = {{x.top, y.bottom, sgn(depth(pp, y.bottom, 0), depth(pp, x.top, 0)), sgn(depth(pp, y.bottom, 1), depth(pp, x.top, 1))},
                          {y.top, x.bottom, sgn(depth(pp, x.bottom, 0), depth(pp, y.top, 0)), sgn(depth(pp, x.bottom, 1), depth(pp, y.top, 1))}};
    for (const Limit& l : lim) {
      if (l.s0 == 0 && l.s1 == 0) return out;                              // touching along a line
      if ((l.s0 < 0 && l.s1 <= 0) || (l.s0 <= 0 && l.s1 < 0)) return out;  // apart (or touching at a pillar)
    }
    // Ends: 0 / 1, or the crossing where a limit turns positive (left) or negative (right).
    const Limit* left = nullptr;
    const Limit* right = nullptr;
    for (const Limit& l : lim) {
      if (l.s0 < 0 && l.s1 > 0 && (!left || crossing(pp, l.top, l.bottom).s > crossing(pp, left->top, left->bottom).s)) left = &l;
      if (l.s0 > 0 && l.s1 < 0 && (!right || crossing(pp, l.top, l.bottom).s < crossing(pp, right->top, right->bottom).s)) right = &l;
    }
    if (left && right && !(crossing(pp, left->top, left->bottom).s < crossing(pp, right->top, right->bottom).s)) return out;
    // The bounding lines at each end: the deeper top (lo) and the shallower bottom (hi); a tie at
    // the end is decided at the other end.
    auto pick = [&](int a, int b, int end, bool deeper) {
      int d = sgn(depth(pp, a, end), depth(pp, b, end));
      if (d == 0) d = sgn(depth(pp, a, 1 - end), depth(pp, b, 1 - end));
      if (!deeper) d = -d;
      return d >= 0 ? a : b;
    };
    const int lo_l = left ? left->top : pick(x.top, y.top, 0, true);
    const int hi_l = left ? left->bottom : pick(x.bottom, y.bottom, 0, false);
    const int lo_r = right ? right->top : pick(x.top, y.top, 1, true);
    const int hi_r = right ? right->bottom : pick(x.bottom, y.bottom, 1, false);
    const int32_t lo_left = left ? crossing(pp, lo_l, hi_l).node : pillar_node(pp.pillar[0], depth(pp, lo_l, 0));
    const int32_t hi_left = left ? lo_left : pillar_node(pp.pillar[0], depth(pp, hi_l, 0));
    const int32_t lo_right = right ? crossing(pp, lo_r, hi_r).node : pillar_node(pp.pillar[1], depth(pp, lo_r, 1));
    const int32_t hi_right = right ? lo_right : pillar_node(pp.pillar[1], depth(pp, hi_r, 1));
    out.push_back(lo_left);
    if (lo_l != lo_r) {
      const int32_t k = crossing(pp, lo_l, lo_r).node;
      along(pp, lo_l, lo_left, k, out);
      along(pp, lo_r, k, lo_right, out);
    } else {
      along(pp, lo_l, lo_left, lo_right, out);
    }
    if (!right) along_pillar(pp.pillar[1], depth(pp, lo_r, 1), depth(pp, hi_r, 1), out);
    if (hi_r != hi_l) {
      const int32_t k = crossing(pp, hi_r, hi_l).node;
      along(pp, hi_r, hi_right, k, out);
      along(pp, hi_l, k, hi_left, out);
    } else {
      along(pp, hi_r, hi_right, hi_left, out);
    }
    if (!left) along_pillar(pp.pillar[0], depth(pp, hi_l, 0), depth(pp, lo_l, 0), out);
    // Close the cycle; collapsed edges (a pinched corner) leave repeated nodes.
    std::vector<int32_t> cyc;
    for (int32_t v : out)
      if (cyc.empty() || cyc.back() != v) cyc.push_back(v);
    while (cyc.size() > 1 && cyc.back() == cyc.front()) cyc.pop_back();
    if (cyc.size() < 3) cyc.clear();
    return cyc;
  }

  // A band's depth range over the strip: its shallowest top end and its deepest bottom end.
  struct Envelope {
    double top, bottom;
  };
  static Envelope envelope(const PillarPair& pp, Band b) {
    return {std::min(depth(pp, b.top, 0), depth(pp, b.top, 1)), std::max(depth(pp, b.bottom, 0), depth(pp, b.bottom, 1))};
  }
  // The envelopes of a column side's bands (or gaps), in the column's order, and whether they go
  // down both pillars, as a column's bands do (check_corner_point_geometry).
  struct Envelopes {
    std::vector<Envelope> e;
    bool ordered = true;
  };
  static Envelopes envelopes(const PillarPair& pp, const std::vector<Band>& bands) {
    Envelopes out;
    for (const Band& b : bands) out.e.push_back(envelope(pp, b));
    for (size_t i = 1; i < out.e.size() && out.ordered; ++i)
      out.ordered = out.e[i - 1].top <= out.e[i].top && out.e[i - 1].bottom <= out.e[i].bottom;
    return out;
  }
  // The bands of `ys` that can share area with band x: band_polygon is empty unless some end of
  // y's bottom is deeper than the same end of x's top and some end of x's bottom deeper than y's top,
  // hence unless y.bottom > x.top and x.bottom > y.top for the envelopes. Ordered envelopes make
  // these bands one range, found by bisection: a pair of columns then costs its faces, not the
  // product of the columns' cells. All of them when ys is not ordered.
  static std::pair<size_t, size_t> overlapping(const Envelopes& ys, Envelope x) {
    if (!ys.ordered) return {0, ys.e.size()};
    const auto lo = std::partition_point(ys.e.begin(), ys.e.end(), [&](const Envelope& y) { return !(y.bottom > x.top); });
    const auto hi = std::partition_point(ys.e.begin(), ys.e.end(), [&](const Envelope& y) { return y.top < x.bottom; });
    return {static_cast<size_t>(lo - ys.e.begin()), static_cast<size_t>(std::max(lo, hi) - ys.e.begin())};
  }

  // The meshed cells of a column (bottom to top order is k), and the gap bands between them.
  std::vector<int> column_cells(int i, int j) const {
    std::vector<int> cells;
    if (i < 0 || j < 0 || i >= m_.nx || j >= m_.ny) return cells;
    for (int k = 0; k < m_.nz; ++k) {
      const int c = i + m_.nx * (j + m_.ny * k);
      if (meshed_[c]) cells.push_back(c);
    }
    return cells;
  }
  std::vector<Band> gaps(const std::vector<int>& cells, int side) const {
    std::vector<Band> g;
    int top = kAbove;
    for (int c : cells) {
      g.push_back({top, line_id(c, side, false)});
      top = line_id(c, side, true);
    }
    g.push_back({top, kBelow});
    return g;
  }

  void pair_faces(int p, int32_t boundary_patch) {
    const PillarPair& pp = pairs_[p];
    const bool is_i = p < n_ipairs();
    // Side A: the column on the -i (-j) side, whose +i (+j) face lies here; B: the other.
    int ia, ja, ib, jb;
    if (is_i) {
      const int I = p % (m_.nx + 1), j = p / (m_.nx + 1);
      ia = I - 1, ja = j, ib = I, jb = j;
    } else {
      const int q = p - n_ipairs(), i = q % m_.nx, J = q / m_.nx;
      ia = i, ja = J - 1, ib = i, jb = J;
    }
    const int side_a = is_i ? 1 : 3, side_b = is_i ? 0 : 2;
    const std::vector<int> ca = column_cells(ia, ja), cb = column_cells(ib, jb);
    auto band = [&](int c, int side) { return Band{line_id(c, side, false), line_id(c, side, true)}; };
    // The walk is outward for A on i-pairs, for B on j-pairs. A piece that is a cell's whole face
    // (all 4 corners of its band) is fanned about that face's own centre (split_face), on both sides.
    auto whole = [&](const std::vector<int32_t>& poly, Band bd, std::array<int32_t, 4>* corner, Vec3* centre) {
      *corner = {pillar_node(pp.pillar[0], depth(pp, bd.top, 0)), pillar_node(pp.pillar[1], depth(pp, bd.top, 1)),
                 pillar_node(pp.pillar[1], depth(pp, bd.bottom, 1)), pillar_node(pp.pillar[0], depth(pp, bd.bottom, 0))};
      if (poly.size() <= 4) return false;
      for (int32_t v : *corner)
        if (std::find(poly.begin(), poly.end(), v) == poly.end()) return false;
      *centre = 0.25 * (pillar_point(m_, pp.pillar[0], depth(pp, bd.top, 0)) + pillar_point(m_, pp.pillar[1], depth(pp, bd.top, 1)) +
                        pillar_point(m_, pp.pillar[1], depth(pp, bd.bottom, 1)) + pillar_point(m_, pp.pillar[0], depth(pp, bd.bottom, 0)));
      return true;
    };
    // poly in walk orientation; `split`: the face is the whole face of one of its cells (corner, centre).
    auto add = [&](int c, bool c_is_a, std::vector<int32_t> poly, int32_t patch, bool split,
                   const std::array<int32_t, 4>& corner, Vec3 centre, int32_t across) {
      if (c_is_a != is_i) std::reverse(poly.begin(), poly.end());
      if (split) {
        split_face(c, poly, corner, centre, patch, across, static_cast<int32_t>(groups_.size()));
        groups_.push_back(std::move(poly));
      } else {
        stage(c, poly.data(), poly.size(), patch, across, -1);
      }
    };
    std::vector<Band> bands_b;
    for (int b : cb) bands_b.push_back(band(b, side_b));
    const Envelopes env_b = envelopes(pp, bands_b);
    for (int a : ca) {
      const auto [first, last] = overlapping(env_b, envelope(pp, band(a, side_a)));
      for (size_t k = first; k < last; ++k) {
        const int b = cb[k];
        std::vector<int32_t> poly = band_polygon(pp, band(a, side_a), band(b, side_b));
        if (poly.empty()) continue;
        if (!(band(a, side_a).top == band(b, side_b).top && band(a, side_a).bottom == band(b, side_b).bottom)) ++fault_faces_;
        std::array<int32_t, 4> corner;
        Vec3 centre;
        const bool split = whole(poly, band(a, side_a), &corner, &centre) || whole(poly, band(b, side_b), &corner, &centre);
        add(a, true, poly, kInteriorFace, split, corner, centre, b);
        add(b, false, std::move(poly), kInteriorFace, split, corner, centre, a);
      }
    }
    const std::vector<Band> ga = gaps(ca, side_a), gb = gaps(cb, side_b);
    // Each cell's face parts toward the other column's gaps (boundary faces).
    auto toward_gaps = [&](const std::vector<int>& cells, int side, const std::vector<Band>& other_gaps, bool is_a) {
      const Envelopes env = envelopes(pp, other_gaps);
      for (int c : cells) {
        const auto [first, last] = overlapping(env, envelope(pp, band(c, side)));
        for (size_t k = first; k < last; ++k)
          if (auto poly = band_polygon(pp, band(c, side), other_gaps[k]); !poly.empty()) {
            std::array<int32_t, 4> corner;
            Vec3 centre;
            const bool split = whole(poly, band(c, side), &corner, &centre);
            add(c, is_a, std::move(poly), boundary_patch, split, corner, centre, -1);
          }
      }
    };
    toward_gaps(ca, side_a, gb, true);
    toward_gaps(cb, side_b, ga, false);
  }

  // Top {0, 2, 3, 1} and bottom {4, 5, 7, 6} faces (outward), every station of their edges named.
  // A face with stations besides its 4 corners (edges crossed on a fault) is split into the triangles
  // from its centre (the mean of its 4 corners) to each of its edges: the surface is then the 4-triangle
  // fan of the plain quad whatever the stations (the mesh's fan of a polygon turns about the mean of
  // all its nodes, which moves with them: on a thin twisted cell the top and bottom fans then crossed
  // and the volume came out negative).
  void top_bottom_faces(int c, int32_t boundary_patch) {
    struct Edge {
      int side;
      bool forward;  // s from 0 to 1
    };
    static const Edge kTop[4] = {{0, true}, {3, true}, {1, false}, {2, false}};
    static const Edge kBottom[4] = {{2, true}, {1, true}, {3, false}, {0, false}};
    const int i = c % m_.nx, j = (c / m_.nx) % m_.ny;
    const std::vector<int> col = column_cells(i, j);
    const auto at = std::find(col.begin(), col.end(), c);
    for (bool bottom : {false, true}) {
      std::vector<int32_t> cyc;
      for (const Edge& e : bottom ? kBottom : kTop) {
        const PillarPair& pp = pairs_[side_pair(c, e.side)];
        const auto& st = pp.stations[line_id(c, e.side, bottom)];
        if (e.forward)
          for (size_t k = 1; k < st.size(); ++k) cyc.push_back(st[k].node);
        else
          for (size_t k = st.size() - 1; k-- > 0;) cyc.push_back(st[k].node);
      }
      std::vector<int32_t> face;
      for (int32_t v : cyc)
        if (face.empty() || face.back() != v) face.push_back(v);
      while (face.size() > 1 && face.back() == face.front()) face.pop_back();
      if (face.size() < 3) continue;
      // Interior when the next meshed cell of the column above (below) has this face's corners.
      int32_t patch = boundary_patch, across = -1;
      const bool has_next = bottom ? (at + 1 != col.end()) : (at != col.begin());
      if (has_next) {
        const int o = bottom ? *(at + 1) : *(at - 1);
        bool same = true;
        for (int q = 0; q < 4; ++q)
          same = same && corner_depth(m_, c, q + (bottom ? 4 : 0)) == corner_depth(m_, o, q + (bottom ? 0 : 4));
        if (same) patch = kInteriorFace, across = o;
      }
      if (face.size() == 4) {
        stage(c, face.data(), face.size(), patch, across, -1);
        continue;
      }
      static const int kQuad[2][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}};
      std::array<int32_t, 4> corner;
      Vec3 centre{0, 0, 0};
      for (int e = 0; e < 4; ++e) {
        const int q = kQuad[bottom][e];
        corner[e] = pillar_node(pillar_of(c, q), corner_depth(m_, c, q));
        centre += corner_point(c, q);
      }
      split_face(c, face, corner, centre / 4.0, patch, across, static_cast<int32_t>(groups_.size()));
      groups_.push_back(std::move(face));
    }
  }

  // A cell face (4 corners) whose cycle has more nodes than its corners, as the triangles from its
  // centre (one node per face, found by its corners) to each of its edges.
  void split_face(int32_t c, const std::vector<int32_t>& cycle, std::array<int32_t, 4> corner, Vec3 centre,
                  int32_t patch, int32_t across, int32_t group) {
    std::sort(corner.begin(), corner.end());
    auto [it, added] = face_centre_.emplace(corner, -1);
    if (added) it->second = b_.add_node(centre);
    for (size_t e = 0; e < cycle.size(); ++e) {
      const int32_t tri[3] = {it->second, cycle[e], cycle[(e + 1) % cycle.size()]};
      stage(c, tri, 3, patch, across, group);
    }
  }
};

}  // namespace

namespace {

// Smallest angle of triangle abc (radians), from its edge lengths.
double min_angle(Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 p[3] = {a, b, c};
  double best = kPiValue;
  for (int k = 0; k < 3; ++k) {
    const Vec3 u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
    const double nu = norm(u), nv = norm(v);
    if (nu == 0 || nv == 0) return 0;
    best = std::min(best, std::acos(std::clamp(dot(u, v) / (nu * nv), -1.0, 1.0)));
  }
  return best;
}

}  // namespace

Vec3 model_cell_corner(const CornerPointModel& model, int c, int q) { return corner(model, static_cast<size_t>(c), q); }

CornerPointCellFaces corner_point_cell_faces(const CornerPointModel& model, const std::vector<char>& present,
                                             MeshBuilder& builder, int32_t boundary_patch) {
  CornerPointMesher mesher(model, present, builder);
  return mesher.cell_faces(boundary_patch);
}

namespace {

using EpickPoint2 = CGAL::Exact_predicates_inexact_constructions_kernel::Point_2;

// Ears whose qualities (smallest angle, radians) differ by less than this are a tie, decided by the
// cycle's order; likewise a node within this fraction of the circle's radius from an ear's circle
// counts as on it. A rectangle's two diagonals are such a tie, and rounding must not decide it: a
// model moved by UTM-sized offsets reaches us with its nodes a few 1e-11 m off, and the same face
// must get the same triangles wherever the model sits (CornerPointSweep.CiHorizontalSurveyWell...).
constexpr double kEarTie = 1e-9;

bool on_circle_within_tie(const EpickPoint2& a, const EpickPoint2& b, const EpickPoint2& c, const EpickPoint2& x) {
  const EpickPoint2 o = CGAL::circumcenter(a, b, c);
  const double r = std::sqrt(CGAL::to_double(CGAL::squared_distance(o, a)));
  return std::abs(std::sqrt(CGAL::to_double(CGAL::squared_distance(o, x))) - r) <= kEarTie * r;
}

}  // namespace

std::vector<std::array<int32_t, 3>> face_triangles(const std::vector<int32_t>& cycle, const std::vector<Vec3>& coords) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  const size_t n = cycle.size();
  if (n < 3) return {};
  if (n == 3) return {{cycle[0], cycle[1], cycle[2]}};
  // The plane of the face: Newell's normal (follows the cycle's orientation), about its first node.
  const Vec3 o = coords[cycle[0]];
  Vec3 nrm{0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const Vec3 a = coords[cycle[i]] - o, b = coords[cycle[(i + 1) % n]] - o;
    nrm += cross(a, b);
  }
  nrm = normalized(nrm);
  const Vec3 ref = std::abs(nrm.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 u = normalized(cross(nrm, ref)), v = cross(nrm, u);  // (u, v, nrm) right-handed
  std::vector<K::Point_2> p2(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 d = coords[cycle[i]] - o;
    p2[i] = K::Point_2(dot(d, u), dot(d, v));
  }
  // Ear clipping in that plane: an ear is a strictly convex corner whose triangle holds no other
  // node (closed); Delaunay ears go first, then the ear with the largest smallest angle (ties within
  // kEarTie: the first in the cycle). Convexity and emptiness are exact predicates on the projected nodes.
  std::vector<size_t> left(n);
  for (size_t i = 0; i < n; ++i) left[i] = i;
  std::vector<std::array<int32_t, 3>> tris;
  while (left.size() > 3) {
    const size_t m = left.size();
    size_t best = m;
    double best_q = -1;
    for (size_t k = 0; k < m; ++k) {
      const size_t a = left[(k + m - 1) % m], b = left[k], c = left[(k + 1) % m];
      if (CGAL::orientation(p2[a], p2[b], p2[c]) != CGAL::LEFT_TURN) continue;
      bool empty = true;
      for (size_t r = 0; r < m && empty; ++r) {
        const size_t x = left[r];
        if (x == a || x == b || x == c) continue;
        empty = !(CGAL::orientation(p2[a], p2[b], p2[x]) != CGAL::RIGHT_TURN &&
                  CGAL::orientation(p2[b], p2[c], p2[x]) != CGAL::RIGHT_TURN &&
                  CGAL::orientation(p2[c], p2[a], p2[x]) != CGAL::RIGHT_TURN);
      }
      if (!empty) continue;
      // Delaunay ears first (no remaining node strictly inside the ear's circle): a convex
      // face then gets its Delaunay triangulation (the sites' spheres cut the plane in those circles).
      bool delaunay = true;
      for (size_t r = 0; r < m && delaunay; ++r) {
        const size_t x = left[r];
        if (x == a || x == b || x == c) continue;
        delaunay = CGAL::side_of_oriented_circle(p2[a], p2[b], p2[c], p2[x]) != CGAL::ON_POSITIVE_SIDE ||
                   on_circle_within_tie(p2[a], p2[b], p2[c], p2[x]);
      }
      const double q = (delaunay ? kPiValue : 0.0) + min_angle(coords[cycle[a]], coords[cycle[b]], coords[cycle[c]]);
      if (q > best_q + kEarTie) best_q = q, best = k;
    }
    if (best == m) throw std::logic_error("corner-point grid: a cell face has no ear to triangulate (degenerate face)");
    tris.push_back({cycle[left[(best + m - 1) % m]], cycle[left[best]], cycle[left[(best + 1) % m]]});
    left.erase(left.begin() + static_cast<std::ptrdiff_t>(best));
  }
  tris.push_back({cycle[left[0]], cycle[left[1]], cycle[left[2]]});
  return tris;
}

std::vector<CavityTriangle> cavity_triangles(const CornerPointCellFaces& cells, int c, const std::vector<char>& active,
                                             const std::vector<Vec3>& coords) {
  std::vector<CavityTriangle> out;
  for (int64_t f = cells.face_begin(c); f < cells.face_end(c); ++f) {
    const int32_t nb = cells.neighbour[f];
    if (nb < 0 || active[nb]) continue;
    // A fanned face (split_face) is triangulated from its cycle, once, without the fan's centre: a
    // centre node in the middle of a cavity wall lies in the spheres of the triangles beside it.
    if (!cells.first_of_its_group(c, f)) continue;
    for (const auto& t : face_triangles(cells.cycle(f), coords)) out.push_back({{t[0], t[1], t[2]}, nb});
  }
  return out;
}

namespace {

// About what add_corner_point_cells adds for the cells it keeps: a face toward another kept cell
// counted once (by the first), every other face once (one toward a cavity becomes a few triangles).
BuilderCapacity corner_point_capacity(const CornerPointCellFaces& cells, const std::vector<char>& active) {
  BuilderCapacity c;
  for (int64_t m = 0; m < cells.n_cells(); ++m) {
    if (!cells.meshed[m] || !active[m]) continue;
    ++c.cells;
    for (int64_t f = cells.face_begin(m); f < cells.face_end(m); ++f) {
      const int32_t nb = cells.neighbour[f];
      const bool shared = nb >= 0 && cells.meshed[nb] && active[nb];
      if (shared && nb < m) continue;  // the face is the first cell's
      ++c.faces;
      c.face_nodes += cells.nodes_end(f) - cells.nodes_begin(f);
    }
  }
  return c;
}

}  // namespace

CornerPointCells add_corner_point_cells(const CornerPointModel& model, const CornerPointCellFaces& cells,
                                        const ReservoirSpec& rock, const std::vector<char>& active,
                                        MeshBuilder& builder, const BuilderCapacity& added_after) {
  const int n = model.nx * model.ny * model.nz;
  std::vector<Vec3> coords(builder.n_nodes());
  for (int32_t i = 0; i < builder.n_nodes(); ++i) coords[i] = builder.node(i);
  const BuilderCapacity own = corner_point_capacity(cells, active);
  builder.reserve(own.cells + added_after.cells, own.faces + added_after.faces,
                  own.face_nodes + added_after.face_nodes);
  CornerPointCells out;
  out.cell_id.assign(n, -1);
  out.zero_volume_cells = cells.zero_volume_cells;
  out.fault_faces = cells.fault_faces;
  out.crossing_nodes = cells.crossing_nodes;
  std::vector<CellFace> faces;  // reused: its node lists keep their storage from cell to cell
  for (int c = 0; c < n; ++c) {
    if (!cells.meshed[c] || !active[c]) continue;
    size_t k = 0;
    auto next = [&]() -> CellFace& {
      if (k == faces.size()) faces.emplace_back();
      return faces[k++];
    };
    for (int64_t f = cells.face_begin(c); f < cells.face_end(c); ++f) {
      const int32_t nb = cells.neighbour[f];
      if (nb >= 0 && !active[nb]) continue;
      CellFace& face = next();
      face.nodes.assign(cells.nodes_begin(f), cells.nodes_end(f));
      face.patch = cells.patch[f];
      face.known_face = -1;
      face.by_id_only = false;
    }
    for (CavityTriangle& t : cavity_triangles(cells, c, active, coords))  // toward a cavity
      next() = CellFace{std::move(t.nodes), kInteriorFace};
    faces.resize(k);
    CellAttributes at;
    at.region = kReservoir;
    Vec3 centre{0, 0, 0};
    for (int q = 0; q < 8; ++q) centre += model_cell_corner(model, c, q);
    at.fv_center = centre / 8.0;
    at.ijk = {c % model.nx, (c / model.nx) % model.ny, c / (model.nx * model.ny)};
    assign_reservoir_rock(rock, c, at);
    out.cell_id[c] = builder.add_cell(faces, at);
  }
  return out;
}

CornerPointCells add_corner_point_cells(const CornerPointModel& model, const ReservoirSpec& rock,
                                        const std::vector<char>& active, MeshBuilder& builder, int32_t boundary_patch) {
  const CornerPointCellFaces cells = corner_point_cell_faces(model, active, builder, boundary_patch);
  return add_corner_point_cells(model, cells, rock, std::vector<char>(cells.meshed.size(), 1), builder);
}

}  // namespace hm
