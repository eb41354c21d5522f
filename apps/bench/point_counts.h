// The benchmarks' --n N,N,... option (header-only, no dependencies: stage_cost.cc is also built
// on its own against older libraries).
#ifndef CAMPROJ_APPS_BENCH_POINT_COUNTS_H_
#define CAMPROJ_APPS_BENCH_POINT_COUNTS_H_

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace camproj {
namespace bench {

// The point counts of "6,8,12"; false (and a message on stderr) if one is below 6.
inline bool ParsePointCounts(const std::string& list, std::vector<int>* counts) {
  counts->clear();
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    const int n = std::atoi(item.c_str());
    if (n < 6) {
      std::cerr << "bench: --n takes point counts >= 6, got \"" << item << "\"\n";
      return false;
    }
    counts->push_back(n);
  }
  return true;
}

}  // namespace bench
}  // namespace camproj

#endif  // CAMPROJ_APPS_BENCH_POINT_COUNTS_H_
