#include "specdeform/spectral/basis_cache.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "linalg/basis_product.h"
#include "specdeform/atomic_file.h"
#include "specdeform/exceptions.h"

namespace specdeform {

namespace {

constexpr char kMagic[8] = {'S', 'D', 'B', 'A', 'S', 'I', 'S', '\0'};
constexpr uint32_t kVersion = 6;  // 1: no Laplacian byte (cotan); 1 and 2: no solver report;
                                  // 1 to 3: exact bases only, no residuals per pair; 1 to 4:
                                  // no pieces and requested modes; 1 to 5: no factored bases
constexpr uint8_t kFactored = 0;  // the scalar byte of a factored basis
constexpr size_t kHeaderSize = 8 + 4 + 4 + 4 + 1 + 1 + 1 + 1 + 8;
constexpr size_t kReportSize = 4 * 8 + 4 + 4 + 8 + 8;

static_assert(std::endian::native == std::endian::little, "the cache format is little-endian");

template <typename T>
void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

template <typename T>
T get(const char*& p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  p += sizeof(T);
  return v;
}

// The factors P (n x N) and Z (N x m) of a factored basis: false where the file ends early;
// throws on indices that do not make a matrix of these sizes.
bool read_factors(std::ifstream& file, const std::string& name, uint32_t n, uint32_t m,
                  FactoredBasis& f) {
  uint32_t N;
  uint64_t nonzeros;
  if (!file.read(reinterpret_cast<char*>(&N), 4) ||
      !file.read(reinterpret_cast<char*>(&nonzeros), 8)) {
    return false;
  }
  if (N == 0 || N > n || nonzeros > uint64_t{std::numeric_limits<int>::max()}) {
    throw InputError(name + ": corrupt basis factors");
  }
  const std::streamoff here = file.tellg();  // nothing allocated beyond what the file holds
  file.seekg(0, std::ios::end);
  const auto left = static_cast<uint64_t>(file.tellg() - here);
  file.seekg(here);
  if (4 * (uint64_t{n} + 1) + 12 * nonzeros + 8 * uint64_t{N} * m > left) return false;
  const auto nnz = static_cast<Eigen::Index>(nonzeros);
  auto& P = f.prolongation;
  P.resize(n, N);
  P.resizeNonZeros(nnz);
  bool ok = file.read(reinterpret_cast<char*>(P.outerIndexPtr()), 4 * (size_t(n) + 1)) &&
            file.read(reinterpret_cast<char*>(P.innerIndexPtr()), 4 * size_t(nnz)) &&
            file.read(reinterpret_cast<char*>(P.valuePtr()), 8 * size_t(nnz));
  if (!ok) return false;
  const int* start = P.outerIndexPtr();
  const int* column = P.innerIndexPtr();
  bool valid = start[0] == 0 && start[n] == nnz;
  for (uint32_t i = 0; valid && i < n; ++i) valid = start[i] <= start[i + 1];
  for (Eigen::Index k = 0; valid && k < nnz; ++k) valid = column[k] >= 0 && uint32_t(column[k]) < N;
  if (!valid) throw InputError(name + ": corrupt basis factors");
  f.coarse.resize(N, m);
  return static_cast<bool>(file.read(reinterpret_cast<char*>(f.coarse.data()), 8 * size_t(N) * m));
}

}  // namespace

uint64_t mesh_hash(const TriangleMesh& mesh) {
  uint64_t h = 1469598103934665603ULL;
  const auto mix = [&h](const void* data, size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  };
  const int n = mesh.num_vertices(), f = mesh.num_faces();
  mix(&n, sizeof n);
  mix(&f, sizeof f);
  mix(mesh.V.data(), sizeof(double) * mesh.V.size());
  mix(mesh.F.data(), sizeof(int) * mesh.F.size());
  return h;
}

void save_basis(const std::filesystem::path& path, const ManifoldHarmonics& basis,
                const TriangleMesh& mesh, BasisPrecision precision) {
  const auto n = static_cast<uint32_t>(basis.basis.rows());
  const auto m = static_cast<uint32_t>(basis.basis.cols());
  if (n != static_cast<uint32_t>(mesh.num_vertices()) || basis.eigenvalues.size() != m) {
    throw InputError(path.string() + ": the basis does not match the mesh it is saved with");
  }
  const bool single = precision == BasisPrecision::Float32;
  const bool factored = basis.factored.smaller_than_dense(single ? 4 : 8);
  if (factored && (basis.factored.prolongation.rows() != n || basis.factored.coarse.cols() != m ||
                   !basis.factored.prolongation.isCompressed())) {
    throw InputError(path.string() + ": the basis's factors do not match the basis");
  }
  const size_t body = factored ? 12 + 4 * (size_t(n) + 1) +
                                     12 * size_t(basis.factored.prolongation.nonZeros()) +
                                     8 * size_t(basis.factored.coarse.size())
                               : (single ? 4 : 8) * size_t(n) * m;
  std::string out;
  out.reserve(kHeaderSize + kReportSize + 8 + 16 * size_t(m) + body);
  out.append(kMagic, 8);
  put(out, kVersion);
  put(out, n);
  put(out, m);
  put(out, static_cast<uint8_t>(basis.mass == MassType::Lumped ? 0 : 1));
  put(out, factored ? kFactored : static_cast<uint8_t>(single ? 4 : 8));
  put(out, static_cast<uint8_t>(basis.laplacian == LaplacianType::Cotan ? 0 : 1));
  put(out, uint8_t{0});
  put(out, mesh_hash(mesh));
  put(out, basis.max_residual);
  put(out, basis.rounding_floor);
  put(out, basis.threshold);
  put(out, basis.max_orthogonality_error);
  put(out, static_cast<uint32_t>(basis.bands));
  put(out, static_cast<uint32_t>(basis.restarts));
  put(out, static_cast<uint64_t>(basis.solves));
  put(out, static_cast<uint8_t>(basis.status == SolveStatus::Converged ? 1 : 0));
  put(out, static_cast<uint8_t>(basis.cluster_truncated ? 1 : 0));
  put(out, static_cast<uint8_t>(basis.approximate ? 1 : 0));
  put(out, static_cast<uint32_t>(basis.coarse_functions));
  out.append(1, '\0');
  put(out, static_cast<uint32_t>(basis.pieces));
  put(out, static_cast<uint32_t>(basis.requested_modes > 0 ? basis.requested_modes : m));
  out.append(reinterpret_cast<const char*>(basis.eigenvalues.data()), 8 * size_t(m));
  const Eigen::VectorXd residuals = basis.residuals.size() == m
                                        ? basis.residuals
                                        : Eigen::VectorXd::Constant(m, basis.max_residual);
  out.append(reinterpret_cast<const char*>(residuals.data()), 8 * size_t(m));
  if (factored) {
    const auto& P = basis.factored.prolongation;
    const Eigen::MatrixXd& Z = basis.factored.coarse;
    put(out, static_cast<uint32_t>(Z.rows()));
    put(out, static_cast<uint64_t>(P.nonZeros()));
    out.append(reinterpret_cast<const char*>(P.outerIndexPtr()), 4 * (size_t(n) + 1));
    out.append(reinterpret_cast<const char*>(P.innerIndexPtr()), 4 * size_t(P.nonZeros()));
    out.append(reinterpret_cast<const char*>(P.valuePtr()), 8 * size_t(P.nonZeros()));
    out.append(reinterpret_cast<const char*>(Z.data()), 8 * size_t(Z.size()));
  } else if (single) {
    const Eigen::MatrixXf H = basis.basis.cast<float>();
    out.append(reinterpret_cast<const char*>(H.data()), 4 * size_t(n) * m);
  } else {
    out.append(reinterpret_cast<const char*>(basis.basis.data()), 8 * size_t(n) * m);
  }
  write_file_atomically(path, out);
}

ManifoldHarmonics load_basis(const std::filesystem::path& path, const TriangleMesh& mesh) {
  const std::string name = path.string();
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(name + ": cannot open basis file");
  char header[kHeaderSize];
  if (!file.read(header, kHeaderSize)) throw InputError(name + ": not a basis file (too short)");
  if (std::memcmp(header, kMagic, 8) != 0) throw InputError(name + ": not a specdeform basis file");
  const char* p = header + 8;
  const auto version = get<uint32_t>(p);
  if (version < 1 || version > kVersion) {
    throw InputError(name + ": basis file version " + std::to_string(version) +
                     " is not supported (this build reads versions 1 to " +
                     std::to_string(kVersion) + ")");
  }
  const auto n = get<uint32_t>(p);
  const auto m = get<uint32_t>(p);
  const auto mass = get<uint8_t>(p);
  const auto scalar = get<uint8_t>(p);
  const auto laplacian = get<uint8_t>(p);
  get<uint8_t>(p);
  const auto hash = get<uint64_t>(p);
  if (n != static_cast<uint32_t>(mesh.num_vertices()) || hash != mesh_hash(mesh)) {
    throw InputError(name + ": the basis belongs to another mesh (" + std::to_string(n) +
                     " vertices, different geometry or faces); recompute it");
  }
  const bool factored = version >= 6 && scalar == kFactored;
  if (mass > 1 || (scalar != 4 && scalar != 8 && !factored) || laplacian > 1 || m == 0 || m > n) {
    throw InputError(name + ": corrupt basis header");
  }
  ManifoldHarmonics out;
  if (version >= 3) {
    char report[kReportSize];
    if (!file.read(report, kReportSize)) throw InputError(name + ": truncated basis file");
    const char* r = report;
    out.max_residual = get<double>(r);
    out.rounding_floor = get<double>(r);
    out.threshold = get<double>(r);
    out.max_orthogonality_error = get<double>(r);
    out.bands = static_cast<int>(get<uint32_t>(r));
    out.restarts = static_cast<int>(get<uint32_t>(r));
    out.solves = static_cast<long long>(get<uint64_t>(r));
    out.status = get<uint8_t>(r) == 1 ? SolveStatus::Converged : SolveStatus::NotConverged;
    out.cluster_truncated = get<uint8_t>(r) == 1;
    out.approximate = get<uint8_t>(r) == 1;
    out.rayleigh_ritz = out.approximate;  // only the multilevel solver writes approximate bases
    out.coarse_functions = static_cast<int>(get<uint32_t>(r));
  } else {
    out.max_residual = std::numeric_limits<double>::quiet_NaN();  // not recorded
  }
  out.pieces = 0;  // not recorded
  out.requested_modes = static_cast<int>(m);
  if (version >= 5) {
    char layout[8];
    if (!file.read(layout, 8)) throw InputError(name + ": truncated basis file");
    const char* r = layout;
    out.pieces = static_cast<int>(get<uint32_t>(r));
    out.requested_modes = static_cast<int>(get<uint32_t>(r));
    if (out.pieces < 1 || out.requested_modes < 1 || out.requested_modes > static_cast<int>(n)) {
      throw InputError(name + ": corrupt basis header");
    }
  }
  out.mass = mass == 0 ? MassType::Lumped : MassType::Consistent;
  out.laplacian = laplacian == 0 ? LaplacianType::Cotan : LaplacianType::IntrinsicDelaunay;
  out.eigenvalues.resize(m);
  if (!factored) out.basis.resize(n, m);
  bool ok =
      static_cast<bool>(file.read(reinterpret_cast<char*>(out.eigenvalues.data()), 8 * size_t(m)));
  out.residuals = Eigen::VectorXd::Constant(m, out.max_residual);
  if (ok && version >= 4) {
    ok = static_cast<bool>(file.read(reinterpret_cast<char*>(out.residuals.data()), 8 * size_t(m)));
  }
  if (ok && factored) {
    ok = read_factors(file, name, n, m, out.factored);
    if (ok) out.basis = detail::factored_product(out.factored);
  } else if (ok && scalar == 8) {
    ok = static_cast<bool>(file.read(reinterpret_cast<char*>(out.basis.data()), 8 * size_t(n) * m));
  } else if (ok) {  // through a small buffer: no float copy of the whole basis
    std::vector<float> chunk(size_t{1} << 18);
    double* to = out.basis.data();
    for (size_t left = size_t(n) * m; ok && left > 0;) {
      const size_t count = std::min(left, chunk.size());
      ok = static_cast<bool>(file.read(reinterpret_cast<char*>(chunk.data()), 4 * count));
      to = std::copy_n(chunk.begin(), count, to);
      left -= count;
    }
  }
  if (!ok) throw InputError(name + ": truncated basis file");
  return out;
}

void require_operators(const std::filesystem::path& path, const ManifoldHarmonics& basis,
                       MassType mass, LaplacianType laplacian) {
  const auto mass_name = [](MassType type) {
    return std::string(type == MassType::Lumped ? "the lumped" : "the consistent") + " mass matrix";
  };
  const auto laplacian_name = [](LaplacianType type) {
    return "the " + std::string(name(type)) + " Laplacian";
  };
  std::string found, wanted;
  if (basis.mass != mass) found = mass_name(basis.mass), wanted = mass_name(mass);
  if (basis.laplacian != laplacian) {
    const std::string both = found.empty() ? "" : " and ";
    found += both + laplacian_name(basis.laplacian);
    wanted += both + laplacian_name(laplacian);
  }
  if (found.empty()) return;
  throw InputError(path.string() + ": the basis was computed with " + found + ", not " + wanted +
                   "; recompute it or ask for the same operators");
}

}  // namespace specdeform
