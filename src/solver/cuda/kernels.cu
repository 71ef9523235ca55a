// The CUDA backend's kernels (compiled by NVRTC when a solver is built; docs/gpu.md).
//
// Grid: Nx x Ny cells, cell i = iy * Nx + ix. A set vector holds one value per site of
// the attached set `set` (ascending cells); `pos[i]` is the cell's position in the set or
// -1.
//
// The operator y = C3(W . C2(x)) + d x, with C2 the unnormalised 2-D DCT-II
// (X_k = sum_n x_n cos(pi k (2n+1) / 2N) along each axis) and C3 = C2^T, each axis by
// Makhoul's algorithm: C2 x = Re(T . F(P x)) with v = P x the even-then-reversed-odd
// order, F the real FFT and T_k = exp(-i pi k / 2N); C2^T Y = P^T F^H(z_H) with z_H the
// Hermitian part of conj(T) . Y: z_H[0] = Y_0, z_H[k] = conj(T_k) (Y_k - i Y_{N-k}) / 2.
// The x axis (rows, contiguous) is transformed first; the y-axis data are stored
// column by column (Nx lines of Ny values) so that both FFTs are batched over contiguous
// lines.
//
// Reductions run in a fixed order (fixed block count, grid-stride loops, a tree in shared
// memory, one block for the final pass), so a run repeats bit for bit on the same GPU.

// Threads per block: kernels.rs's THREADS, given by the compiler's -DTHREADS (NVRTC's and
// the emulator's alike), so that the block size of the launches and of the trees below is
// one value.
#ifndef THREADS
#error "THREADS (threads per block) comes from kernels.rs: compile with -DTHREADS=..."
#endif

// The position of source index n in Makhoul's order v (v[m] = x[perm(m)]).
__device__ __forceinline__ int makhoul_source(int m, int n) {
    return (m < (n + 1) / 2) ? 2 * m : 2 * (n - 1 - m) + 1;
}

// Where x[j] lands in Makhoul's order.
__device__ __forceinline__ int makhoul_slot(int j, int n) {
    return (j % 2 == 0) ? j / 2 : n - 1 - (j - 1) / 2;
}

// T_k = exp(-i pi k / 2n) applied to (re, im), real part only.
__device__ __forceinline__ double twiddle_re(double re, double im, int k, int n) {
    double s, c;
    sincospi((double)k / (2.0 * n), &s, &c);
    return c * re + s * im;
}

// Element k of a full length-n spectrum held as its first n/2 + 1 values (Hermitian).
__device__ __forceinline__ double2 hermitian_at(const double2* half, int k, int n) {
    if (k <= n / 2) return half[k];
    double2 v = half[n - k];
    v.y = -v.y;
    return v;
}

// z_H[k] of C2^T from the real spectrum Y (Y_n := 0 is never read: k >= 1 reads n - k).
__device__ __forceinline__ double2 inverse_input(double yk, double ynk, int k, int n) {
    double2 out;
    if (k == 0) {
        out.x = yk;
        out.y = 0.0;
        return out;
    }
    // conj(T_k) = cos + i sin (angle pi k / 2n); (Y_k - i Y_{n-k}) / 2.
    double s, c;
    sincospi((double)k / (2.0 * n), &s, &c);
    double a = 0.5 * yk, b = -0.5 * ynk;
    out.x = c * a - s * b;
    out.y = c * b + s * a;
    return out;
}

// Step 1: the set vector x scattered onto the grid (zero off the set), rows in Makhoul's
// order. v: Ny x Nx.
extern "C" __global__ void scatter_rows(const double* x, const int* pos, double* v, int nx, int ny) {
    int idx = blockIdx.x * blockDim.x + threadIdx.x;
    if (idx >= nx * ny) return;
    int iy = idx / nx, m = idx % nx;
    int p = pos[iy * nx + makhoul_source(m, nx)];
    v[idx] = p >= 0 ? x[p] : 0.0;
}

// Step 3: the x-axis DCT-II from the rows' spectra (Ny x (Nx/2 + 1)), written column by
// column in Makhoul's order along y. u: Nx x Ny.
extern "C" __global__ void rows_to_columns(const double2* spec, double* u, int nx, int ny) {
    int idx = blockIdx.x * blockDim.x + threadIdx.x;
    if (idx >= nx * ny) return;
    int kx = idx / ny, m = idx % ny;
    int iy = makhoul_source(m, ny);
    double2 v = hermitian_at(spec + (size_t)iy * (nx / 2 + 1), kx, nx);
    u[idx] = twiddle_re(v.x, v.y, kx, nx);
}

// The 2-D coefficient (ky, kx) of C2 x from the columns' spectra (Nx x (Ny/2 + 1)).
__device__ __forceinline__ double column_coefficient(const double2* spec, int kx, int ky, int ny) {
    double2 v = hermitian_at(spec + (size_t)kx * (ny / 2 + 1), ky, ny);
    return twiddle_re(v.x, v.y, ky, ny);
}

// Step 5: the diagonal W (Ny x Nx, row-major) applied and the y-axis C2^T prepared:
// out[kx][k] = z_H[k] of the column kx of W . C2 x, k = 0 .. Ny/2.
extern "C" __global__ void filter_columns(const double2* spec, const double* table, double2* out,
                                          int nx, int ny) {
    int half = ny / 2 + 1;
    int idx = blockIdx.x * blockDim.x + threadIdx.x;
    if (idx >= nx * half) return;
    int kx = idx / half, k = idx % half;
    double yk = table[(size_t)k * nx + kx] * column_coefficient(spec, kx, k, ny);
    double ynk = 0.0;
    if (k > 0) {
        int j = ny - k;
        ynk = table[(size_t)j * nx + kx] * column_coefficient(spec, kx, j, ny);
    }
    out[idx] = inverse_input(yk, ynk, k, ny);
}

// Step 7: after the y-axis inverse (w: Nx x Ny, Makhoul's order along y), the x-axis
// C2^T prepared: out[iy][k] = z_H[k] of row iy, k = 0 .. Nx/2.
extern "C" __global__ void columns_to_rows(const double* w, double2* out, int nx, int ny) {
    int half = nx / 2 + 1;
    int idx = blockIdx.x * blockDim.x + threadIdx.x;
    if (idx >= ny * half) return;
    int iy = idx / half, k = idx % half;
    int slot = makhoul_slot(iy, ny);
    double yk = w[(size_t)k * ny + slot];
    double ynk = k > 0 ? w[(size_t)(nx - k) * ny + slot] : 0.0;
    out[idx] = inverse_input(yk, ynk, k, nx);
}

// Step 9: the product on the set, y[j] = s(cell of j) (+ d[j] x[j] when with_d; s: Ny x Nx,
// rows in Makhoul's order).
extern "C" __global__ void gather_set(const double* s, const int* set, const double* d,
                                      const double* x, double* y, int with_d, int m, int nx) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    int i = set[j];
    int iy = i / nx, ix = i % nx;
    double v = s[(size_t)iy * nx + makhoul_slot(ix, nx)];
    y[j] = with_d ? v + d[j] * x[j] : v;
}

// The product on every cell (the displacements' C_s f after a solve).
extern "C" __global__ void gather_grid(const double* s, double* out, int nx, int ny) {
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= nx * ny) return;
    int iy = i / nx, ix = i % nx;
    out[i] = s[(size_t)iy * nx + makhoul_slot(ix, nx)];
}

// The residual's tail: r = y + offset - b.
extern "C" __global__ void residual_tail(double* r, const double* b, double offset, int m) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    r[j] += offset - b[j];
}

// Jacobi: z = r / (diag_c + d).
extern "C" __global__ void jacobi(const double* r, const double* d, double diag_c, double* z, int m) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    z[j] = r[j] / (diag_c + d[j]);
}

// The CG's local updates of a phase, in the order of pcg.rs's `Pre::apply`. Flags:
// 1 keep_best, 2 restore_best, 4 shift_f, 8 step, 16 step updates r, 32 project,
// 64 w = z, 128 p = -z, 256 p = beta p - z, 512 r = 1.
extern "C" __global__ void pre_updates(double* f, double* r, double* z, double* p, const double* q,
                                       double* w, double* best, int flags, double shift,
                                       double alpha, double u, double beta, int m) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    double fj = f[j];
    if (flags & 1) best[j] = fj;
    if (flags & 2) fj = best[j];
    if (flags & 4) fj += shift;
    if (flags & 8) {
        fj += alpha * p[j];
        if (flags & 16) r[j] += alpha * q[j];
    }
    f[j] = fj;
    if (flags & 32) {
        z[j] += u * w[j];
        r[j] += u;
    }
    if (flags & 64) w[j] = z[j];
    if (flags & 128) p[j] = -z[j];
    if (flags & 256) p[j] = beta * p[j] - z[j];
    if (flags & 512) r[j] = 1.0;
}

// Reductions. mode 0: sum a; 1: sum a b; 2: max |a|, max |b|, sum a c (three values).
__device__ __forceinline__ void reduce_terms(int mode, const double* a, const double* b,
                                             const double* c, int j, double* acc) {
    if (mode == 0) {
        acc[0] += a[j];
    } else if (mode == 1) {
        acc[0] += a[j] * b[j];
    } else {
        acc[0] = fmax(acc[0], fabs(a[j]));
        acc[1] = fmax(acc[1], fabs(b[j]));
        acc[2] += a[j] * c[j];
    }
}

__device__ __forceinline__ void combine(int mode, double* acc, const double* other) {
    if (mode == 2) {
        acc[0] = fmax(acc[0], other[0]);
        acc[1] = fmax(acc[1], other[1]);
        acc[2] += other[2];
    } else {
        acc[0] += other[0];
    }
}

// The tree of one block over shared memory (3 x THREADS values); thread 0 ends with it.
__device__ void block_tree(int mode, double* acc, double* shared) {
    int t = threadIdx.x;
    for (int v = 0; v < 3; v++) shared[v * THREADS + t] = acc[v];
    __syncthreads();
    for (int width = THREADS / 2; width > 0; width /= 2) {
        if (t < width) {
            double mine[3], other[3];
            for (int v = 0; v < 3; v++) {
                mine[v] = shared[v * THREADS + t];
                other[v] = shared[v * THREADS + t + width];
            }
            combine(mode, mine, other);
            for (int v = 0; v < 3; v++) shared[v * THREADS + t] = mine[v];
        }
        __syncthreads();
    }
    for (int v = 0; v < 3; v++) acc[v] = shared[v * THREADS];
}

// First pass: partials[3 * block + v] over a fixed grid-stride split of 0 .. m.
extern "C" __global__ void reduce_partial(int mode, const double* a, const double* b,
                                          const double* c, int m, double* partials) {
    __shared__ double shared[3 * THREADS];
    double acc[3] = {0.0, 0.0, 0.0};
    for (int j = blockIdx.x * THREADS + threadIdx.x; j < m; j += gridDim.x * THREADS)
        reduce_terms(mode, a, b, c, j, acc);
    block_tree(mode, acc, shared);
    if (threadIdx.x == 0)
        for (int v = 0; v < 3; v++) partials[3 * blockIdx.x + v] = acc[v];
}

// Second pass, one block: out[v] over the blocks' partials in a fixed order.
extern "C" __global__ void reduce_final(int mode, const double* partials, int blocks, double* out) {
    __shared__ double shared[3 * THREADS];
    double acc[3] = {0.0, 0.0, 0.0};
    for (int k = threadIdx.x; k < blocks; k += THREADS) {
        double other[3] = {partials[3 * k], partials[3 * k + 1], partials[3 * k + 2]};
        combine(mode, acc, other);
    }
    block_tree(mode, acc, shared);
    if (threadIdx.x == 0)
        for (int v = 0; v < 3; v++) out[v] = acc[v];
}

// FSAI (solver/fsai.rs): M^-1 = G^T G with G stored as one weight plane per pattern slot,
// planes[k * n + i] the weight of cell i on cell i - offsets[k] (zero off the set and for
// missing neighbours); the last slot is the site itself (offset 0). The sums run in
// fsai.rs's order: the site's own slot first, then the slots downward.

// The host's refreshed rows onto the planes: weights[c * stride + k] is row cells[c]'s
// weight in slot k.
extern "C" __global__ void fsai_scatter(const int* cells, const double* weights, int count,
                                        double* planes, int stride, int n) {
    int t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= count * stride) return;
    int c = t / stride, k = t % stride;
    planes[(size_t)k * n + cells[c]] = weights[t];
}

// y = G r on the set: y[j] = sum_k w_k[i] r(i - o_k), i = set[j].
extern "C" __global__ void fsai_g(const double* planes, const int* offsets, int stride,
                                  const int* set, const int* pos, const double* r, double* y,
                                  int m, int n) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    int i = set[j];
    double acc = planes[(size_t)(stride - 1) * n + i] * r[j];
    for (int k = stride - 2; k >= 0; k--) {
        double w = planes[(size_t)k * n + i];
        int c = i - offsets[k];
        if (w == 0.0 || c < 0) continue;
        int p = pos[c];
        if (p >= 0) acc += w * r[p];
    }
    y[j] = acc;
}

// z = G^T y on the set: z[j] = sum_k w_k[i + o_k] y(i + o_k), i = set[j].
extern "C" __global__ void fsai_gt(const double* planes, const int* offsets, int stride,
                                   const int* set, const int* pos, const double* y, double* z,
                                   int m, int n) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    int i = set[j];
    double acc = planes[(size_t)(stride - 1) * n + i] * y[j];
    for (int k = stride - 2; k >= 0; k--) {
        int c = i + offsets[k];
        if (c >= n) continue;
        double w = planes[(size_t)k * n + c];
        if (w == 0.0) continue;
        int p = pos[c];
        if (p >= 0) acc += w * y[p];
    }
    z[j] = acc;
}

// The coarse space of the two-level preconditioner (solver/coarse.rs; A-DEF2 in the CG).
// Aggregates are the blocks of block x block cells, bx along x, count in all. The device
// keeps E = Z^T A Z over all of them (row-major; an empty aggregate's row is the
// identity's), its Cholesky factor, its inverse, w = E^-1 c and info = [valid, c^T w]
// (c: the aggregates' site counts).

__device__ __forceinline__ int aggregate_of(int cell, int nx, int block, int bx) {
    return (cell / nx / block) * bx + (cell % nx) / block;
}

// x = the indicator of aggregate a's sites, on the set.
extern "C" __global__ void coarse_indicator(const int* set, int m, int nx, int block, int bx,
                                            int a, double* x) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    x[j] = aggregate_of(set[j], nx, block, bx) == a ? 1.0 : 0.0;
}

// The restriction Z^T (v - t) (t when subtract) or Z^T v: one block of threads per
// aggregate b, its cells in a fixed order, then the block's tree. Into E's column and row
// `column` when column >= 0 (count x count), else into out[b].
extern "C" __global__ void coarse_restrict(const double* v, const double* t, int subtract,
                                           const int* pos, int nx, int ny, int block, int bx,
                                           double* out, int column, int count) {
    __shared__ double shared[3 * THREADS];
    int b = blockIdx.x;
    int x0 = (b % bx) * block, y0 = (b / bx) * block;
    int w = min(block, nx - x0), h = min(block, ny - y0);
    double acc[3] = {0.0, 0.0, 0.0};
    for (int c = threadIdx.x; c < w * h; c += THREADS) {
        int p = pos[(y0 + c / w) * nx + x0 + c % w];
        if (p >= 0) acc[0] += subtract ? v[p] - t[p] : v[p];
    }
    block_tree(0, acc, shared);
    if (threadIdx.x != 0) return;
    if (column >= 0) {
        out[(size_t)b * count + column] = acc[0];
        out[(size_t)column * count + b] = acc[0];
    } else {
        out[b] = acc[0];
    }
}

// An empty aggregate's row and column of E are zero: its diagonal becomes 1, so that E
// stays definite and the aggregate's coarse value 0.
extern "C" __global__ void coarse_fix_empty(double* e, const double* c, int count) {
    int a = blockIdx.x * blockDim.x + threadIdx.x;
    if (a < count && c[a] == 0.0) e[(size_t)a * count + a] = 1.0;
}

// E = L L^T in place (the lower triangle of l, count x count; one block of threads, the
// pivots in order); info[0] = 1 when every pivot is positive and finite, else 0.
extern "C" __global__ void coarse_factor(double* l, int k, double* info) {
    __shared__ int ok;
    if (threadIdx.x == 0) ok = 1;
    __syncthreads();
    for (int p = 0; p < k; p++) {
        if (threadIdx.x == 0) {
            double d = l[(size_t)p * k + p];
            if (d > 0.0 && isfinite(d))
                l[(size_t)p * k + p] = sqrt(d);
            else
                ok = 0;
        }
        __syncthreads();
        if (!ok) break;
        double pivot = l[(size_t)p * k + p];
        for (int q = p + 1 + threadIdx.x; q < k; q += THREADS) l[(size_t)q * k + p] /= pivot;
        __syncthreads();
        for (int q = p + 1 + threadIdx.x; q < k; q += THREADS) {
            double lqp = l[(size_t)q * k + p];
            for (int r = p + 1; r <= q; r++) l[(size_t)q * k + r] -= lqp * l[(size_t)r * k + p];
        }
        __syncthreads();
    }
    if (threadIdx.x == 0) info[0] = ok ? 1.0 : 0.0;
}

// E^-1 from its factor, one thread per column q: L y = e_q, then L^T x = y, x written to
// inv[p * k + q] (adjacent threads, adjacent values).
extern "C" __global__ void coarse_invert(const double* l, int k, double* inv) {
    int q = blockIdx.x * blockDim.x + threadIdx.x;
    if (q >= k) return;
    for (int p = 0; p < q; p++) inv[(size_t)p * k + q] = 0.0;
    for (int p = q; p < k; p++) {
        double s = p == q ? 1.0 : 0.0;
        for (int r = q; r < p; r++) s -= l[(size_t)p * k + r] * inv[(size_t)r * k + q];
        inv[(size_t)p * k + q] = s / l[(size_t)p * k + p];
    }
    for (int p = k - 1; p >= 0; p--) {
        double s = inv[(size_t)p * k + q];
        for (int r = p + 1; r < k; r++) s -= l[(size_t)r * k + p] * inv[(size_t)r * k + q];
        inv[(size_t)p * k + q] = s / l[(size_t)p * k + p];
    }
}

// out = E^-1 x (E^-1 symmetric: row a read as column a, adjacent threads adjacent values).
__device__ void inverse_product(const double* inv, const double* x, int k, double* out) {
    for (int a = threadIdx.x; a < k; a += THREADS) {
        double s = 0.0;
        for (int b = 0; b < k; b++) s += inv[(size_t)b * k + a] * x[b];
        out[a] = s;
    }
}

// w = E^-1 c and info[1] = c^T w; info[0] cleared unless c^T w is positive and finite.
// One block of threads.
// c^T x over the block's threads (strided terms, then the block's tree: a fixed order).
__device__ double block_dot(const double* c, const double* x, int k) {
    __shared__ double shared[3 * THREADS];
    double acc[3] = {0.0, 0.0, 0.0};
    for (int a = threadIdx.x; a < k; a += THREADS) acc[0] += c[a] * x[a];
    block_tree(0, acc, shared);
    return acc[0];
}

extern "C" __global__ void coarse_border(const double* inv, const double* c, int k, double* w,
                                         double* info) {
    inverse_product(inv, c, k, w);
    __syncthreads();
    double cw = block_dot(c, w, k);
    if (threadIdx.x != 0) return;
    info[1] = cw;
    if (!(cw > 0.0 && isfinite(cw))) info[0] = 0.0;
}

// The bordered coarse solve of g (solver/coarse.rs): y = E^-1 g, mu = c^T y / c^T w,
// sol = y - mu w. One block of threads.
extern "C" __global__ void coarse_solve(const double* inv, const double* g, const double* c,
                                        const double* w, const double* info, int k, double* sol) {
    inverse_product(inv, g, k, sol);
    __syncthreads();
    double mu = block_dot(c, sol, k) / info[1];
    for (int a = threadIdx.x; a < k; a += THREADS) sol[a] -= mu * w[a];
}

// x[j] += sign * sol[the aggregate of set[j]].
extern "C" __global__ void coarse_prolong(double* x, const double* sol, double sign,
                                          const int* set, int m, int nx, int block, int bx) {
    int j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j >= m) return;
    x[j] += sign * sol[aggregate_of(set[j], nx, block, bx)];
}
