#pragma once
// C doubles per element, added and scaled element by element: several right-hand sides carried
// through one pass over a scene's links (each link read once for all of them), where Rgb carries
// one emission's three channels. Its operators are Rgb's, so code templated on the value type
// (the gather, push and pull over a hierarchy, the link solve) takes either.
#include <array>
#include <cstddef>

namespace radiosa {

template <int C>
struct Channels {
    std::array<double, C> v{};

    Channels() = default;
    explicit Channels(double x) { v.fill(x); }
    static constexpr int length() { return C; }
    double& operator[](int i) { return v[static_cast<std::size_t>(i)]; }
    double operator[](int i) const { return v[static_cast<std::size_t>(i)]; }

    Channels& operator+=(const Channels& o) {
        for (int i = 0; i < C; ++i) v[i] += o.v[i];
        return *this;
    }
    Channels& operator-=(const Channels& o) {
        for (int i = 0; i < C; ++i) v[i] -= o.v[i];
        return *this;
    }
    Channels& operator*=(double s) {
        for (int i = 0; i < C; ++i) v[i] *= s;
        return *this;
    }
    friend Channels operator+(Channels a, const Channels& b) { return a += b; }
    friend Channels operator-(Channels a, const Channels& b) { return a -= b; }
    friend Channels operator*(double s, Channels a) { return a *= s; }
    friend Channels operator*(Channels a, double s) { return a *= s; }
    friend Channels operator/(Channels a, double s) {
        for (int i = 0; i < C; ++i) a.v[i] /= s;
        return a;
    }
    friend Channels operator*(Channels a, const Channels& b) {  // element by element
        for (int i = 0; i < C; ++i) a.v[i] *= b.v[i];
        return a;
    }
};

}  // namespace radiosa
