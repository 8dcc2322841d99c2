// Writes the Ptex test files of pbrs (tests/inputs/ptex/*.ptx) with the Ptex
// library pbrt-v3 builds, and prints lookups made as pbrt-v3's PtexTexture
// makes them (bspline filter, premultiplied cache) for tests/textures_ptex.rs.
// Build and run from this directory:
//   g++ -O1 -o /tmp/ptexgen gen.cpp -I/work/pbrt-v3/src/ext/ptex/src/ptex \
//       /work/pbrt-v3/build/src/ext/ptex/src/ptex/libPtex.a -lz -lpthread
//   /tmp/ptexgen > lookups.txt
#include <Ptexture.h>
#include <PtexHalf.h>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <vector>
using namespace Ptex;

static float pattern(int f, int c, int x, int y, int w, int h) {
    float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
    switch (f % 4) {
    case 0: return 0.2f + 0.6f * u * (c == 0) + 0.6f * v * (c == 1) + 0.3f * (c == 2);
    case 1: return ((x / 2 + y / 2) & 1) ? 0.9f - 0.2f * c : 0.1f + 0.1f * c;
    case 2: return 0.5f + 0.45f * std::sin(6.2831853f * (u * (c + 1) + 2 * v));
    default: return ((x ^ y) & 4) ? 0.25f + 0.2f * c * u : 0.75f - 0.3f * v;
    }
}

struct Face { int ulog2, vlog2; bool constant; int adj[4]; int edge[4]; };

template <typename T>
static T conv(float v);
template <> uint8_t conv<uint8_t>(float v) { return (uint8_t)std::lround(v * 255.f); }
template <> uint16_t conv<uint16_t>(float v) { return PtexHalf(v).bits; }
template <> float conv<float>(float v) { return v * 1.5f; }

template <typename T>
static void write(const char* path, DataType dt, int nch, const std::vector<Face>& faces,
                  BorderMode bu, BorderMode bv) {
    String err;
    PtexWriter* w = PtexWriter::open(path, mt_quad, dt, nch, -1, (int)faces.size(), err);
    if (!w) { fprintf(stderr, "%s\n", err.c_str()); exit(1); }
    w->setBorderModes(bu, bv);
    w->writeMeta("generator", "pbrs tests/inputs/ptex/gen.cpp");
    for (size_t f = 0; f < faces.size(); f++) {
        const Face& fc = faces[f];
        int adj[4], edge[4];
        for (int i = 0; i < 4; i++) adj[i] = fc.adj[i], edge[i] = fc.edge[i];
        FaceInfo info(Res(fc.ulog2, fc.vlog2), adj, edge);
        int W = 1 << fc.ulog2, H = 1 << fc.vlog2;
        if (fc.constant) {
            std::vector<T> px(nch);
            for (int c = 0; c < nch; c++) px[c] = conv<T>(0.15f + 0.3f * c + 0.1f * f);
            w->writeConstantFace((int)f, info, px.data());
            continue;
        }
        std::vector<T> d((size_t)W * H * nch);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                for (int c = 0; c < nch; c++)
                    d[((size_t)y * W + x) * nch + c] = conv<T>(pattern((int)f + nch, c, x, y, W, H));
        w->writeFace((int)f, info, d.data());
    }
    if (!w->close(err)) { fprintf(stderr, "%s\n", err.c_str()); exit(1); }
    w->release();
}

struct Lookup { int face; float u, v, dudx, dvdx, dudy, dvdy; };

static void lookups(PtexCache* cache, const char* path, const std::vector<Lookup>& ls) {
    String err;
    PtexTexture* t = cache->get(path, err);
    if (!t) { fprintf(stderr, "%s\n", err.c_str()); exit(1); }
    int nc = t->numChannels();
    for (int f = 0; f < t->numFaces(); f++) {
        const FaceInfo& fi = t->getFaceInfo(f);
        float px[4];
        int W = fi.res.u(), H = fi.res.v();
        int pts[3][2] = {{0, 0}, {W - 1, H / 2}, {W / 3, H - 1}};
        for (auto& p : pts) {
            t->getPixel(f, p[0], p[1], px, 0, nc);
            printf("pixel %s %d %d %d", path, f, p[0], p[1]);
            for (int c = 0; c < nc; c++) printf(" %.9g", px[c]);
            printf("\n");
        }
    }
    PtexFilter::Options opts(PtexFilter::f_bspline);
    PtexFilter* filter = PtexFilter::getFilter(t, opts);
    for (const Lookup& l : ls) {
        float r[4] = {0, 0, 0, 0};
        filter->eval(r, 0, nc, l.face, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
        printf("eval %s %d %.9g %.9g %.9g %.9g %.9g %.9g", path, l.face, l.u, l.v, l.dudx, l.dvdx,
               l.dudy, l.dvdy);
        for (int c = 0; c < nc; c++) printf(" %.9g", r[c]);
        printf("\n");
    }
    filter->release();
    t->release();
}

int main() {
    // A 2x2 grid of quads (face = 2*row + col; edges bottom, right, top, left).
    std::vector<Face> grid = {
        {3, 3, false, {-1, 1, 2, -1}, {0, 3, 0, 0}},
        {4, 2, false, {-1, -1, 3, 0}, {0, 0, 0, 1}},
        {8, 8, false, {0, 3, -1, -1}, {2, 3, 0, 0}},
        {5, 5, true, {1, -1, -1, 2}, {2, 0, 0, 1}},
    };
    write<uint8_t>("rgb8.ptx", dt_uint8, 3, grid, m_clamp, m_clamp);
    std::vector<Face> grid1 = grid;
    grid1[0].constant = true;
    grid1[3].constant = false;
    write<uint16_t>("gray16f.ptx", dt_half, 1, grid1, m_clamp, m_clamp);
    std::vector<Face> grid2 = grid;
    grid2[1].ulog2 = 2; grid2[1].vlog2 = 5;
    grid2[2].ulog2 = 6; grid2[2].vlog2 = 6;
    write<float>("rgb32f.ptx", dt_float, 3, grid2, m_clamp, m_clamp);
    // An L of three faces: face 1 (right of face 0) is rotated, its bottom
    // edge on face 0's right edge; face 2 is above face 0. The corner they
    // share is on the boundary (valence 3).
    std::vector<Face> ell = {
        {4, 4, false, {-1, 1, 2, -1}, {0, 0, 0, 0}},
        {3, 4, false, {0, -1, -1, -1}, {1, 0, 0, 0}},
        {4, 3, false, {0, -1, -1, -1}, {2, 0, 0, 0}},
    };
    write<uint8_t>("ell8.ptx", dt_uint8, 3, ell, m_black, m_periodic);

    PtexCache* cache = PtexCache::create(100, 1ull << 32, true);
    std::vector<Lookup> ls;
    float uvs[][2] = {{0.5f, 0.5f}, {0.03f, 0.61f}, {0.97f, 0.2f}, {0.4f, 0.98f}, {0.02f, 0.01f},
                      {0.99f, 0.97f}, {0.25f, 0.75f}, {0.01f, 0.99f}, {0.995f, 0.004f}};
    float ds[][4] = {{0, 0, 0, 0}, {0.01f, 0, 0, 0.01f}, {0.03f, 0.01f, -0.02f, 0.05f},
                     {0.2f, 0, 0, 0.1f}, {0.4f, 0.1f, 0, 0.3f}, {0.8f, 0, 0, 0.9f}, {1.5f, 0, 0, 2},
                     {0.002f, 0.05f, 0.003f, -0.004f}, {0.07f, -0.2f, 0.01f, 0.02f},
                     {0.13f, 0.002f, 0.001f, 0.6f}, {3.f, 0.5f, 0, 0.05f}};
    for (int f = 0; f < 4; f++)
        for (auto& uv : uvs)
            for (auto& d : ds) ls.push_back({f, uv[0], uv[1], d[0], d[1], d[2], d[3]});
    lookups(cache, "rgb8.ptx", ls);
    lookups(cache, "gray16f.ptx", ls);
    lookups(cache, "rgb32f.ptx", ls);
    std::vector<Lookup> ls3;
    for (auto& l : ls)
        if (l.face < 3) ls3.push_back(l);
    ls3.push_back({0, -0.3f, 1.4f, 0.01f, 0, 0, 0.01f});
    ls3.push_back({1, 2.5f, 0.5f, 0.01f, 0, 0, 0.01f});
    lookups(cache, "ell8.ptx", ls3);
    cache->release();
    return 0;
}
