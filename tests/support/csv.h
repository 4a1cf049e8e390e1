// Test support: reading the CSV files granflow writes (header row, comma-separated numbers).
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace granflow::test
{
  /// Columns of a CSV with a header row.
  inline std::vector<std::vector<double>>
  read_csv(const std::string &file)
  {
    std::ifstream                    in(file);
    std::string                      line;
    std::vector<std::vector<double>> columns;
    std::getline(in, line);
    while (std::getline(in, line))
      {
        std::stringstream s(line);
        std::string       cell;
        for (std::size_t j = 0; std::getline(s, cell, ','); ++j)
          {
            if (columns.size() <= j)
              columns.emplace_back();
            columns[j].push_back(std::stod(cell));
          }
      }
    return columns;
  }
} // namespace granflow::test
