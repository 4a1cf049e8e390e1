// Binary dump / load of a ConeProblemData on streams, for replaying a solve offline (bench/).
#include "solvers/cone_problem.h"

#include <algorithm>
#include <cstdint>
#include <istream>
#include <ostream>
#include <stdexcept>

namespace granflow::solvers
{
  namespace
  {
    constexpr std::uint64_t magic = 0x67666c6f77636f6eULL; // "gflowcon"

    template <typename T>
    void
    write_vector(std::ostream &out, const std::vector<T> &v)
    {
      const std::uint64_t size = v.size();
      out.write(reinterpret_cast<const char *>(&size), sizeof(size));
      out.write(reinterpret_cast<const char *>(v.data()), sizeof(T) * size);
    }

    template <typename T>
    void
    read_vector(std::istream &in, std::vector<T> &v)
    {
      std::uint64_t size = 0;
      in.read(reinterpret_cast<char *>(&size), sizeof(size));
      // a corrupt size is not allocated: what is left of a file bounds it (a pipe cannot tell)
      if (const auto here = in.tellg(); in && here != std::streampos(-1))
        {
          in.seekg(0, std::ios::end);
          const auto end = in.tellg();
          in.seekg(here);
          if (!in || size > static_cast<std::uint64_t>(end - here) / sizeof(T))
            {
              in.setstate(std::ios::failbit);
              return;
            }
        }
      v.resize(size);
      in.read(reinterpret_cast<char *>(v.data()), sizeof(T) * size);
    }

    void
    write_matrix(std::ostream &out, const CsrMatrix &M)
    {
      const std::uint64_t dims[2] = {M.n_rows, M.n_cols};
      out.write(reinterpret_cast<const char *>(dims), sizeof(dims));
      write_vector(out, M.row_start);
      write_vector(out, M.column);
      write_vector(out, M.value);
    }

    void
    read_matrix(std::istream &in, CsrMatrix &M)
    {
      std::uint64_t dims[2] = {0, 0};
      in.read(reinterpret_cast<char *>(dims), sizeof(dims));
      M.n_rows = dims[0];
      M.n_cols = dims[1];
      read_vector(in, M.row_start);
      read_vector(in, M.column);
      read_vector(in, M.value);
    }
  } // namespace

  void
  write_cone_problem(const ConeProblemData &data, std::ostream &out)
  {
    const std::uint64_t header[2] = {magic, data.block_size};
    out.write(reinterpret_cast<const char *>(header), sizeof(header));
    write_matrix(out, data.A);
    write_matrix(out, data.H);
    write_vector(out, data.l);
    write_vector(out, data.k);
    write_vector(out, data.mu);
    write_vector(out, data.Bi);
    write_vector(out, data.gamma_scale);
  }

  ConeProblemData
  read_cone_problem(std::istream &in)
  {
    std::uint64_t header[2] = {0, 0};
    in.read(reinterpret_cast<char *>(header), sizeof(header));
    if (header[0] != magic)
      throw std::runtime_error("is not a granflow cone problem dump");
    ConeProblemData data;
    if (header[1] != 3 && header[1] != 6)
      throw std::runtime_error("has cone blocks of " + std::to_string(header[1]) +
                               " components, not 3 (2D) or 6 (3D): a corrupt dump");
    data.block_size = static_cast<unsigned int>(header[1]);
    read_matrix(in, data.A);
    read_matrix(in, data.H);
    read_vector(in, data.l);
    read_vector(in, data.k);
    read_vector(in, data.mu);
    read_vector(in, data.Bi);
    if (in.peek() != std::char_traits<char>::eof()) // dumps before session 12 end here
      read_vector(in, data.gamma_scale);
    if (!in)
      throw std::runtime_error("is truncated");
    // The sizes and indices the solvers rely on, so that a corrupt file is refused here rather
    // than read out of bounds.
    const auto valid = [](const CsrMatrix &M) {
      if (M.row_start.empty() || M.row_start.size() - 1 != M.n_rows || M.row_start.front() != 0 ||
          static_cast<std::size_t>(M.row_start.back()) != M.column.size() ||
          M.value.size() != M.column.size())
        return false;
      for (std::size_t i = 0; i < M.n_rows; ++i)
        if (M.row_start[i] > M.row_start[i + 1])
          return false;
      return std::all_of(M.column.begin(), M.column.end(),
                         [&](const auto c) { return static_cast<std::uint64_t>(c) < M.n_cols; });
    };
    if (!valid(data.A) || !valid(data.H) || data.A.n_rows != data.A.n_cols ||
        data.H.n_cols != data.A.n_rows || data.l.size() != data.A.n_rows ||
        data.k.size() != data.H.n_rows || data.block_size == 0 ||
        data.mu.size() * data.block_size != data.H.n_rows || data.Bi.size() != data.mu.size())
      throw std::runtime_error("is not a consistent cone problem (corrupt dump)");
    if (!data.gamma_scale.empty() && data.gamma_scale.size() != data.mu.size())
      throw std::runtime_error("has " + std::to_string(data.gamma_scale.size()) +
                               " residual scales for " + std::to_string(data.mu.size()) +
                               " points");
    return data;
  }
} // namespace granflow::solvers
