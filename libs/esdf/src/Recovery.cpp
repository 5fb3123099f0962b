#include "urbanslam/esdf/Recovery.h"

#include <cholmod.h>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "PathSolve.h"
#include "SparseInverse.h"

namespace urbanslam::esdf {

namespace {
// CHOLMOD (Debian's build) opens OpenMP parallel regions in its numeric factorisation. With no
// active levels allowed they run on the calling thread: measured on w10000, the thread
// wake-ups cost ~20 % of the back end's time, and the filter is meant to use one core. The
// previous setting is restored, so code elsewhere in the process keeps its own parallelism.
class SerialOpenMp {
 public:
  SerialOpenMp() : levels_(omp_get_max_active_levels()) { omp_set_max_active_levels(0); }
  ~SerialOpenMp() { omp_set_max_active_levels(levels_); }
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;

 private:
  int levels_;
};
}  // namespace

namespace {

// Doubles kept in an unnamed temporary file (deleted when closed), in memory when the file
// cannot be written.
class KeptValues {
 public:
  KeptValues() = default;
  KeptValues(const KeptValues&) = delete;
  KeptValues& operator=(const KeptValues&) = delete;
  ~KeptValues() {
    if (file_) std::fclose(file_);
  }
  void keep(std::vector<double> values) {
    count_ = values.size();
    memory_.clear();
    memory_.shrink_to_fit();
    if (!file_) file_ = std::tmpfile();
    if (file_ && std::fseek(file_, 0, SEEK_SET) == 0 && std::fwrite(values.data(), sizeof(double), count_, file_) == count_ &&
        std::fflush(file_) == 0) {
      in_file_ = true;
      return;
    }
    in_file_ = false;
    memory_ = std::move(values);
  }
  std::vector<double> read() const {
    if (!in_file_) return memory_;
    std::vector<double> out(count_);
    if (std::fseek(file_, 0, SEEK_SET) != 0 || std::fread(out.data(), sizeof(double), count_, file_) != count_)
      throw std::runtime_error("the factorised matrix's values could not be read back from their temporary file");
    return out;
  }

 private:
  std::FILE* file_ = nullptr;
  bool in_file_ = false;
  size_t count_ = 0;
  std::vector<double> memory_;
};

}  // namespace

struct SparseCholesky::Impl {
  cholmod_common common;
  cholmod_factor* factor = nullptr;
  FillReducingOrdering ordering;
  double nested_dissection_min_flops;
  bool nested_dissection = false;  // the current factor's ordering
  // Pattern of the last analysed matrix: the symbolic factor is reused when it is unchanged.
  std::vector<int> last_p, last_i;
  // Its values at the last factorisation, read only to save the filter (matrix()): written to an
  // unnamed temporary file rather than held (8 of the 12 bytes per non-zero of the matrix's lower
  // triangle), or held when no temporary file can be written.
  KeptValues last_x;
  // The factor as SupernodalFactorView reads it (view()) and its FactorIndex (index()): built on
  // first use after a factorisation.
  std::vector<int> simplicial_columns;
  std::optional<SupernodalFactorView> view;
  std::unique_ptr<FactorIndex> index;
  std::vector<int> path_workspace;  // pathSolve's, one entry per supernode

  Impl(FillReducingOrdering o, double nd_min_flops) : ordering(o), nested_dissection_min_flops(nd_min_flops) {
    cholmod_start(&common);
    switch (o) {
      case FillReducingOrdering::Amd:
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_AMD;
        break;
      case FillReducingOrdering::Metis:
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_METIS;
        break;
      case FillReducingOrdering::Natural:
        common.nmethods = 1;
        common.method[0].ordering = CHOLMOD_NATURAL;
        break;
      case FillReducingOrdering::Auto:
        break;  // cholmod_start's defaults
    }
    common.postorder = 1;
    common.print = 0;
  }
  ~Impl() {
    if (factor) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }

  // The symbolic factor of `a` with the configured ordering; with AMD on a pattern whose
  // factorisation it makes dear, METIS's ordering too, the one with fewer operations kept (both
  // deterministic: a saved matrix factorised again chooses the same).
  cholmod_factor* analyze(cholmod_sparse* a) {
    cholmod_factor* f = cholmod_analyze(a, &common);
    if (!f) throw std::runtime_error("CHOLMOD analyze failed (status " + std::to_string(common.status) + ")");
    nested_dissection = f->ordering == CHOLMOD_METIS;
    if (ordering != FillReducingOrdering::Amd || nested_dissection_min_flops <= 0 || common.fl < nested_dissection_min_flops) return f;
    const double amd_flops = common.fl, amd_lnz = common.lnz;
    common.method[0].ordering = CHOLMOD_METIS;
    cholmod_factor* nd = cholmod_analyze(a, &common);
    common.method[0].ordering = CHOLMOD_AMD;
    if (nd && common.status == CHOLMOD_OK && nd->ordering == CHOLMOD_METIS && common.fl < amd_flops) {
      cholmod_free_factor(&f, &common);
      nested_dissection = true;
      return nd;
    }
    if (nd) cholmod_free_factor(&nd, &common);
    common.status = CHOLMOD_OK;
    common.fl = amd_flops;
    common.lnz = amd_lnz;
    return f;
  }
};

SparseCholesky::SparseCholesky(FillReducingOrdering ordering, double nested_dissection_min_flops)
    : impl_(std::make_unique<Impl>(ordering, nested_dissection_min_flops)) {}
SparseCholesky::~SparseCholesky() = default;

bool SparseCholesky::valid() const { return impl_->factor != nullptr; }

void SparseCholesky::factorize(const InformationState& s, int first, int last) {
  if (first < 0 || last > s.size() || first >= last) throw std::invalid_argument("factorize: bad pose range");
  const int poses = last - first;
  const size_t n = 3 * static_cast<size_t>(poses);
  // Lower triangle (stype = -1), column by column: for block column p, the lower part of the
  // diagonal block, then the blocks Lambda(o, p) of linked poses o > p in the range (sorted).
  // (CHOLMOD's supernodal factorisation transposes a lower-stored matrix once, an upper-stored
  // one twice.)
  // Sized exactly first: grown by doubling, the arrays held up to half as much again as the
  // matrix while CHOLMOD factorised it, when the whole map's memory peaks.
  size_t entries = 0;
  for (int p = first; p < last; ++p) {
    entries += 6;
    for (const auto& l : s.links(p))
      if (l.other > p && l.other < last) entries += 9;
  }
  std::vector<int> colptr(n + 1, 0);
  std::vector<int> rowind;
  std::vector<double> values;
  rowind.reserve(entries);
  values.reserve(entries);
  std::vector<std::pair<int, const Mat3*>> higher;
  for (int p = first; p < last; ++p) {
    higher.clear();
    for (const auto& l : s.links(p))
      if (l.other > p && l.other < last) higher.emplace_back(l.other, &l.block);
    std::sort(higher.begin(), higher.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const Mat3& d = s.diagonal(p);
    for (int c = 0; c < 3; ++c) {
      for (int r = c; r < 3; ++r) {
        rowind.push_back(3 * (p - first) + r);
        values.push_back(d(r, c));
      }
      for (const auto& [o, blk] : higher) {
        // Lambda(o, p) = Lambda(p, o)' : entry (row r of o, col c of p) = blk(c, r).
        for (int r = 0; r < 3; ++r) {
          rowind.push_back(3 * (o - first) + r);
          values.push_back((*blk)(c, r));
        }
      }
      colptr[3 * (p - first) + c + 1] = static_cast<int>(rowind.size());
    }
  }
  factorizeLower(std::move(colptr), std::move(rowind), std::move(values));
  first_ = first;
  last_ = last;
  stamp_ = s.structureStamp();
}

void SparseCholesky::factorizeLower(std::vector<int> colptr, std::vector<int> rowind, std::vector<double> values) {
  const size_t n = colptr.size() - 1;
  cholmod_sparse a{};
  a.nrow = a.ncol = n;
  a.nzmax = rowind.size();
  a.p = colptr.data();
  a.i = rowind.data();
  a.x = values.data();
  a.stype = -1;
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_REAL;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;

  cholmod_common* cm = &impl_->common;
  const SerialOpenMp serial;
  const bool same_pattern = impl_->factor && colptr == impl_->last_p && rowind == impl_->last_i;
  if (same_pattern) {
    // The kept pattern is the same: the new copy goes before the factorisation.
    a.p = impl_->last_p.data();
    a.i = impl_->last_i.data();
    std::vector<int>().swap(colptr);
    std::vector<int>().swap(rowind);
  } else {
    if (impl_->factor) cholmod_free_factor(&impl_->factor, cm);
    impl_->factor = impl_->analyze(&a);
    impl_->last_p = std::move(colptr);
    impl_->last_i = std::move(rowind);
  }
  impl_->view.reset();
  impl_->index.reset();
  cholmod_factorize(&a, impl_->factor, cm);
  if (cm->status != CHOLMOD_OK || impl_->factor->minor < n) {
    cholmod_free_factor(&impl_->factor, cm);
    impl_->last_p.clear();
    throw NotPositiveDefinite("information matrix is not positive definite (CHOLMOD status " + std::to_string(cm->status) + ")");
  }
  impl_->last_x.keep(std::move(values));
}

SparseCholesky::Matrix SparseCholesky::matrix() const {
  Matrix m;
  if (!impl_->factor) return m;
  m.first = first_;
  m.last = last_;
  m.structure_stamp = stamp_;
  m.colptr = impl_->last_p;
  m.rowind = impl_->last_i;
  m.values = impl_->last_x.read();
  return m;
}

void SparseCholesky::factorize(const Matrix& m) {
  if (m.first < 0 || m.last <= m.first) throw std::invalid_argument("factorize: bad pose range");
  const size_t n = 3 * static_cast<size_t>(m.last - m.first);
  if (m.colptr.size() != n + 1 || m.colptr.front() != 0 || m.rowind.size() != m.values.size() ||
      static_cast<size_t>(m.colptr.back()) != m.rowind.size())
    throw std::invalid_argument("factorize: inconsistent matrix sizes");
  // All column pointers first: non-decreasing from 0 to the row count keeps every column's
  // range inside the row indices before any is read.
  for (size_t c = 0; c < n; ++c)
    if (m.colptr[c + 1] < m.colptr[c]) throw std::invalid_argument("factorize: decreasing column pointers");
  for (size_t c = 0; c < n; ++c) {
    // Lower triangle, sorted rows, the diagonal first (as factorize(state) builds it): a column
    // without its diagonal cannot belong to a positive definite matrix.
    if (m.colptr[c + 1] == m.colptr[c] || m.rowind[static_cast<size_t>(m.colptr[c])] != static_cast<int>(c))
      throw std::invalid_argument("factorize: column " + std::to_string(c) + " lacks its diagonal");
    for (int k = m.colptr[c]; k < m.colptr[c + 1]; ++k) {
      const int r = m.rowind[static_cast<size_t>(k)];
      if (r < static_cast<int>(c) || static_cast<size_t>(r) >= n || (k > m.colptr[c] && r <= m.rowind[static_cast<size_t>(k) - 1]))
        throw std::invalid_argument("factorize: row index out of order");
    }
  }
  // A fresh analysis of the same pattern is the one a reused analysis came from (both
  // deterministic), so the factor is the same.
  if (impl_->factor) cholmod_free_factor(&impl_->factor, &impl_->common);
  impl_->last_p.clear();
  impl_->last_i.clear();
  factorizeLower(m.colptr, m.rowind, m.values);
  first_ = m.first;
  last_ = m.last;
  stamp_ = m.structure_stamp;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& b) const {
  if (!impl_->factor) throw std::logic_error("solve without a factor");
  cholmod_common* cm = &impl_->common;
  const SerialOpenMp serial;
  Eigen::MatrixXd rhs = b;
  cholmod_dense bd{};
  bd.nrow = static_cast<size_t>(rhs.rows());
  bd.ncol = static_cast<size_t>(rhs.cols());
  bd.nzmax = bd.nrow * bd.ncol;
  bd.d = bd.nrow;
  bd.x = rhs.data();
  bd.xtype = CHOLMOD_REAL;
  bd.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, impl_->factor, &bd, cm);
  if (!x) throw std::runtime_error("CHOLMOD solve failed");
  Eigen::MatrixXd out = Eigen::Map<Eigen::MatrixXd>(static_cast<double*>(x->x), rhs.rows(), rhs.cols());
  cholmod_free_dense(&x, cm);
  return out;
}

bool SparseCholesky::supernodal() const { return impl_->factor && impl_->factor->is_super; }

bool SparseCholesky::nestedDissection() const { return impl_->factor && impl_->nested_dissection; }

SupernodalFactorView SparseCholesky::view() const {
  if (!impl_->factor) throw std::logic_error("no factor to read");
  if (impl_->view) return *impl_->view;  // (read once per factorisation)
  cholmod_common* cm = &impl_->common;
  const cholmod_factor* f = impl_->factor;
  SupernodalFactorView v;
  v.columns = static_cast<int>(f->n);
  v.perm = static_cast<const int*>(f->Perm);
  if (f->is_super) {
    v.supernodes = static_cast<int>(f->nsuper);
    v.first_column = static_cast<const int*>(f->super);
    v.row_begin = static_cast<const int*>(f->pi);
    v.rows = static_cast<const int*>(f->s);
    v.value_begin = static_cast<const int*>(f->px);
    v.values = static_cast<const double*>(f->x);
    impl_->view = v;
    return v;
  }
  std::vector<int>& columns = impl_->simplicial_columns;
  columns.resize(f->n + 1);
  for (size_t c = 0; c <= f->n; ++c) columns[c] = static_cast<int>(c);
  v.supernodes = v.columns;
  v.first_column = columns.data();
  // A simplicial factor is read in place, its columns made to lie in order, each where the next
  // begins (one column per supernode); CHOLMOD packs them within the factor's own arrays (the
  // solves read it either way). A copy would hold a second factor while it is read.
  cholmod_factor* l = impl_->factor;
  if (!cholmod_change_factor(static_cast<int>(l->xtype), static_cast<int>(l->is_ll), 0, 1, 1, l, cm))
    throw std::runtime_error("CHOLMOD could not pack the factor (status " + std::to_string(cm->status) + ")");
  v.unit_diagonal_ldl = !l->is_ll;
  v.row_begin = static_cast<const int*>(l->p);
  v.rows = static_cast<const int*>(l->i);
  v.value_begin = static_cast<const int*>(l->p);
  v.values = static_cast<const double*>(l->x);
  impl_->view = v;
  return v;
}

std::vector<Mat3> SparseCholesky::inverseDiagonalBlocks() const {
  if (!impl_->factor) throw std::logic_error("inverseDiagonalBlocks without a factor");
  const SupernodalFactorView v = view();
  return esdf::inverseDiagonalBlocks(v, index(v));
}

const FactorIndex& SparseCholesky::index(const SupernodalFactorView& v) const {
  if (!impl_->index) {
    impl_->index = std::make_unique<FactorIndex>(v);
    impl_->path_workspace.assign(static_cast<size_t>(v.supernodes), -1);
  }
  return *impl_->index;
}

double SparseCholesky::inverseWork() const {
  if (!impl_->factor) throw std::logic_error("inverseWork without a factor");
  return esdf::inverseWork(view());
}

double SparseCholesky::factorisationWork() const {
  if (!impl_->factor) throw std::logic_error("factorisationWork without a factor");
  return esdf::factorisationWork(view());
}

PathSolution SparseCholesky::pathSolve(int pose) const {
  if (!impl_->factor) throw std::logic_error("pathSolve without a factor");
  const SupernodalFactorView v = view();
  const FactorIndex& ix = index(v);
  return esdf::pathSolve(v, ix, impl_->path_workspace, pose);
}

Mat3 SparseCholesky::covarianceBetween(const PathSolution& a, const PathSolution& b) { return pathCovariance(a, b); }

long long SparseCholesky::factorNonZeros() const {
  if (!impl_->factor) return 0;
  const cholmod_factor* f = impl_->factor;
  if (f->is_super) {
    // Supernodal: sum over supernodes of (rows x cols) lower-trapezoid storage.
    long long nz = 0;
    const int* super = static_cast<const int*>(f->super);
    const int* pi = static_cast<const int*>(f->pi);
    for (size_t k = 0; k < f->nsuper; ++k) {
      const long long cols = super[k + 1] - super[k], rows = pi[k + 1] - pi[k];
      nz += cols * rows - cols * (cols - 1) / 2;
    }
    return nz;
  }
  const int* colcount = static_cast<const int*>(f->ColCount);
  long long nz = 0;
  for (size_t j = 0; j < f->n; ++j) nz += colcount[j];
  return nz;
}

}  // namespace urbanslam::esdf
