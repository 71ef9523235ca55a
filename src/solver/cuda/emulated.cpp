// kernels.cu run on the host, for the tests of src/solver/cuda/emulated.rs: blocks run one
// after the other, each of THREADS threads (below), and the batched FFTs are
// naive DFTs in long double. The launch
// sequence is operator.rs's `Transforms::filter` and `gather_set`/`gather_grid`.
//
// Input (stdin, whitespace separated), for the products: "operator nx ny m with_d", the
// table (Ny x Nx), then m lines of "cell x d". Output (stdout): the m values of the set
// product, then the Nx·Ny values of the grid product (cell order). Modes "pre" and "fsai"
// below run the CG's local updates and the FSAI product.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

// Threads per block, given as -DTHREADS as NVRTC is given it (emulated.rs: kernels.rs's
// THREADS, and fewer): 1 (each block one thread, `__syncthreads` a no-op), or more, run
// as real threads meeting at a barrier for `__syncthreads`, so that a missing or
// misplaced barrier in a kernel shows.
#ifndef THREADS
#error "compile with -DTHREADS=..."
#endif

struct double2 {
    double x, y;
};
struct Dim {
    unsigned x, y, z;
};
static Dim blockIdx, blockDim, gridDim;
#if THREADS > 1
#include <barrier>
#include <thread>
static thread_local Dim threadIdx;
static std::barrier<>* block_barrier;
#define __syncthreads() block_barrier->arrive_and_wait()
#else
static Dim threadIdx;
#define __syncthreads()
#endif
#define __device__
#define __forceinline__ inline
#define __global__
#define __shared__ static
static inline void sincospi(double a, double* s, double* c) {
    long double pi = 3.141592653589793238462643383279502884L;
    *s = (double)std::sin(pi * a);
    *c = (double)std::cos(pi * a);
}
using std::fabs;
using std::fmax;
using std::isfinite;
using std::min;
using std::sqrt;
#include "kernels.cu"

// Runs `blocks` blocks of THREADS threads each, one block after the other.
template <class F>
static void launch(size_t blocks, F kernel) {
    blockDim = {THREADS, 1, 1};
    gridDim = {(unsigned)blocks, 1, 1};
    for (size_t b = 0; b < blocks; b++) {
        blockIdx = {(unsigned)b, 0, 0};
#if THREADS > 1
        std::barrier<> barrier(THREADS);
        block_barrier = &barrier;
        std::vector<std::thread> threads;
        for (unsigned t = 0; t < THREADS; t++)
            threads.emplace_back([&kernel, t] {
                threadIdx = {t, 0, 0};
                kernel();
            });
        for (auto& t : threads) t.join();
#else
        threadIdx = {0, 0, 0};
        kernel();
#endif
    }
}

// Blocks of one thread per element of n (operator.rs's `over`).
static size_t over(size_t n) { return (n + THREADS - 1) / THREADS; }

static const long double PI = 3.141592653589793238462643383279502884L;

// cufftExecD2Z: batch lines of n reals -> n/2 + 1 complex values each.
static void d2z(const std::vector<double>& in, std::vector<double2>& out, int n, int batch) {
    int half = n / 2 + 1;
    for (int b = 0; b < batch; b++)
        for (int k = 0; k < half; k++) {
            long double re = 0, im = 0;
            for (int j = 0; j < n; j++) {
                long double a = -2 * PI * (long double)((long long)j * k % n) / n;
                re += in[(size_t)b * n + j] * std::cos(a);
                im += in[(size_t)b * n + j] * std::sin(a);
            }
            out[(size_t)b * half + k] = {(double)re, (double)im};
        }
}

// cufftExecZ2D: batch Hermitian half spectra -> n reals each, unnormalised.
static void z2d(const std::vector<double2>& in, std::vector<double>& out, int n, int batch) {
    int half = n / 2 + 1;
    for (int b = 0; b < batch; b++)
        for (int j = 0; j < n; j++) {
            long double s = 0;
            for (int k = 0; k < n; k++) {
                double2 z = k < half ? in[(size_t)b * half + k] : in[(size_t)b * half + (n - k)];
                long double zi = k < half ? z.y : -z.y;
                long double a = 2 * PI * (long double)((long long)j * k % n) / n;
                s += z.x * std::cos(a) - zi * std::sin(a);
            }
            out[(size_t)b * n + j] = (double)s;
        }
}

// "pre m flags shift alpha u beta", then m lines "f r z p q w best": the vectors after
// pre_updates, one line per site.
static int pre() {
    int m, flags;
    double shift, alpha, u, beta;
    if (std::scanf("%d %d %lf %lf %lf %lf", &m, &flags, &shift, &alpha, &u, &beta) != 6) return 2;
    std::vector<double> v[7];
    for (auto& x : v) x.resize(m);
    for (int j = 0; j < m; j++)
        for (auto& x : v)
            if (std::scanf("%lf", &x[j]) != 1) return 2;
    launch(over(m), [&] {
        pre_updates(v[0].data(), v[1].data(), v[2].data(), v[3].data(), v[4].data(), v[5].data(),
                    v[6].data(), flags, shift, alpha, u, beta, m);
    });
    for (int j = 0; j < m; j++) {
        for (auto& x : v) std::printf("%.17g ", x[j]);
        std::printf("\n");
    }
    return 0;
}

// y = the set product of x (with d x when with_d) and grid = the product on every cell:
// operator.rs's launch sequence (`Transforms::filter`, then `gather_set`, `gather_grid`).
static void product(const std::vector<double>& table, const std::vector<double>& x,
                    const std::vector<int>& set, const std::vector<int>& pos,
                    const std::vector<double>& d, std::vector<double>& y,
                    std::vector<double>& grid, int with_d, int nx, int ny) {
    size_t n = (size_t)nx * ny;
    int m = (int)set.size();
    std::vector<double> real_a(n), real_b(n);
    std::vector<double2> rows((size_t)ny * (nx / 2 + 1)), columns((size_t)nx * (ny / 2 + 1)),
        filtered((size_t)nx * (ny / 2 + 1));
    launch(over(n), [&] { scatter_rows(x.data(), pos.data(), real_a.data(), nx, ny); });
    d2z(real_a, rows, nx, ny);
    launch(over(n), [&] { rows_to_columns(rows.data(), real_b.data(), nx, ny); });
    d2z(real_b, columns, ny, nx);
    launch(over((size_t)nx * (ny / 2 + 1)),
           [&] { filter_columns(columns.data(), table.data(), filtered.data(), nx, ny); });
    z2d(filtered, real_a, ny, nx);
    launch(over((size_t)ny * (nx / 2 + 1)), [&] { columns_to_rows(real_a.data(), rows.data(), nx, ny); });
    z2d(rows, real_b, nx, ny);
    launch(over(m), [&] { gather_set(real_b.data(), set.data(), d.data(), x.data(), y.data(), with_d, m, nx); });
    launch(over(n), [&] { gather_grid(real_b.data(), grid.data(), nx, ny); });
}

// "coarse nx ny block bx count", the operator's table (Ny x Nx), "rounds R", then per
// round "m", m lines "cell d", "columns K" and K aggregates: the device's coarse upkeep
// (DeviceCoarse::update) for each round's set, E kept from round to round: the listed
// columns of E from the products of their indicators, the empty aggregates fixed, the
// factor, the inverse, the border. Then m values r on the last set: its restriction, the
// bordered solve, and r with the solution prolonged (sign +1). Output: info[0] info[1],
// E (count x count), the solution (count), the prolonged r (m).
static int coarse() {
    int nx, ny, block, bx, count, rounds;
    if (std::scanf("%d %d %d %d %d", &nx, &ny, &block, &bx, &count) != 5) return 2;
    size_t n = (size_t)nx * ny;
    std::vector<double> table(n);
    for (auto& t : table)
        if (std::scanf("%lf", &t) != 1) return 2;
    size_t kk = (size_t)count * count;
    std::vector<double> e(kk, 0.0), l(kk), inv(kk), c(count), w(count), g(count), sol(count),
        info(2);
    std::vector<int> set, pos(n, -1);
    std::vector<double> d, x, y, grid(n);
    if (std::scanf(" rounds %d", &rounds) != 1) return 2;
    for (int round = 0; round < rounds; round++) {
        int m, columns;
        if (std::scanf("%d", &m) != 1) return 2;
        set.assign(m, 0);
        d.assign(m, 0.0);
        x.assign(m, 0.0);
        y.assign(m, 0.0);
        pos.assign(n, -1);
        for (int j = 0; j < m; j++) {
            if (std::scanf("%d %lf", &set[j], &d[j]) != 2) return 2;
            pos[set[j]] = j;
        }
        c.assign(count, 0.0);
        for (int j = 0; j < m; j++) c[aggregate_of(set[j], nx, block, bx)] += 1.0;
        if (std::scanf(" columns %d", &columns) != 1) return 2;
        for (int k = 0; k < columns; k++) {
            int a;
            if (std::scanf("%d", &a) != 1) return 2;
            launch(over(m), [&] { coarse_indicator(set.data(), m, nx, block, bx, a, x.data()); });
            product(table, x, set, pos, d, y, grid, 1, nx, ny);
            launch(count, [&] {
                coarse_restrict(y.data(), y.data(), 0, pos.data(), nx, ny, block, bx, e.data(), a,
                                count);
            });
        }
        launch(over(count), [&] { coarse_fix_empty(e.data(), c.data(), count); });
        l = e;
        launch(1, [&] { coarse_factor(l.data(), count, info.data()); });
        launch(over(count), [&] { coarse_invert(l.data(), count, inv.data()); });
        launch(1, [&] { coarse_border(inv.data(), c.data(), count, w.data(), info.data()); });
    }
    int m = (int)set.size();
    std::vector<double> r(m);
    for (auto& v : r)
        if (std::scanf("%lf", &v) != 1) return 2;
    launch(count, [&] {
        coarse_restrict(r.data(), r.data(), 0, pos.data(), nx, ny, block, bx, g.data(), -1, count);
    });
    launch(1, [&] {
        coarse_solve(inv.data(), g.data(), c.data(), w.data(), info.data(), count, sol.data());
    });
    launch(over(m), [&] { coarse_prolong(r.data(), sol.data(), 1.0, set.data(), m, nx, block, bx); });
    std::printf("%.17g %.17g\n", info[0], info[1]);
    for (double v : e) std::printf("%.17g\n", v);
    for (double v : sol) std::printf("%.17g\n", v);
    for (double v : r) std::printf("%.17g\n", v);
    return 0;
}

// "fsai nx ny stride", the stride offsets, "rounds R", then per round "count" and count
// lines "cell w_0 .. w_{stride-1}" (fsai_scatter onto zero planes, round after round),
// then "m" and m lines "cell r": z = G^T G r on the set, one value per line.
static int fsai() {
    int nx, ny, stride, rounds;
    if (std::scanf("%d %d %d", &nx, &ny, &stride) != 3) return 2;
    int n = nx * ny;
    std::vector<int> offsets(stride);
    for (auto& o : offsets)
        if (std::scanf("%d", &o) != 1) return 2;
    std::vector<double> planes((size_t)stride * n, 0.0);
    if (std::scanf(" rounds %d", &rounds) != 1) return 2;
    for (int k = 0; k < rounds; k++) {
        int count;
        if (std::scanf("%d", &count) != 1) return 2;
        std::vector<int> cells(count);
        std::vector<double> weights((size_t)count * stride);
        for (int c = 0; c < count; c++) {
            if (std::scanf("%d", &cells[c]) != 1) return 2;
            for (int s = 0; s < stride; s++)
                if (std::scanf("%lf", &weights[(size_t)c * stride + s]) != 1) return 2;
        }
        launch(over((size_t)count * stride), [&] {
            fsai_scatter(cells.data(), weights.data(), count, planes.data(), stride, n);
        });
    }
    int m;
    if (std::scanf("%d", &m) != 1) return 2;
    std::vector<int> set(m), pos(n, -1);
    std::vector<double> r(m), y(m), z(m);
    for (int j = 0; j < m; j++) {
        if (std::scanf("%d %lf", &set[j], &r[j]) != 2) return 2;
        pos[set[j]] = j;
    }
    launch(over(m), [&] {
        fsai_g(planes.data(), offsets.data(), stride, set.data(), pos.data(), r.data(), y.data(), m, n);
    });
    launch(over(m), [&] {
        fsai_gt(planes.data(), offsets.data(), stride, set.data(), pos.data(), y.data(), z.data(), m, n);
    });
    for (int j = 0; j < m; j++) std::printf("%.17g\n", z[j]);
    return 0;
}

int main() {
    char mode[16];
    if (std::scanf("%15s", mode) != 1) return 2;
    if (std::string(mode) == "pre") return pre();
    if (std::string(mode) == "fsai") return fsai();
    if (std::string(mode) == "coarse") return coarse();
    int nx, ny, m, with_d;
    if (std::scanf("%d %d %d %d", &nx, &ny, &m, &with_d) != 4) return 2;
    size_t n = (size_t)nx * ny;
    std::vector<double> table(n), x(m), d(m), y(m), grid(n);
    std::vector<int> set(m), pos(n, -1);
    for (size_t i = 0; i < n; i++)
        if (std::scanf("%lf", &table[i]) != 1) return 2;
    for (int j = 0; j < m; j++) {
        if (std::scanf("%d %lf %lf", &set[j], &x[j], &d[j]) != 3) return 2;
        pos[set[j]] = j;
    }
    product(table, x, set, pos, d, y, grid, with_d, nx, ny);
    for (int j = 0; j < m; j++) std::printf("%.17g\n", y[j]);
    for (size_t i = 0; i < n; i++) std::printf("%.17g\n", grid[i]);
    // The reductions over y (modes 0, 1 with x, 2 with y, x, y), blocks as the device's
    // first pass splits them (here one thread each).
    std::vector<double> partials(3 * 7), out(3);
    for (int mode = 0; mode < 3; mode++) {
        const double* a = y.data();
        const double* b = mode == 1 ? x.data() : x.data();
        launch(7, [&] { reduce_partial(mode, a, b, y.data(), m, partials.data()); });
        launch(1, [&] { reduce_final(mode, partials.data(), 7, out.data()); });
        std::printf("%.17g %.17g %.17g\n", out[0], out[1], out[2]);
    }
    return 0;
}
