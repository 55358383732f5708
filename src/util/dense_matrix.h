#pragma once
// A square row-major matrix of doubles. Kept free of Eigen so that headers stay cheap to
// include; the solver maps it into Eigen where it needs linear algebra.
#include <cstddef>
#include <vector>

namespace radiosa {

struct DenseMatrix {
    int n = 0;
    std::vector<double> data;

    DenseMatrix() = default;
    explicit DenseMatrix(int size) : n(size), data(static_cast<std::size_t>(size) * size, 0.0) {}

    double& operator()(int i, int j) { return data[static_cast<std::size_t>(i) * n + j]; }
    double operator()(int i, int j) const { return data[static_cast<std::size_t>(i) * n + j]; }
};

}  // namespace radiosa
