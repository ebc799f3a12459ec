// bench/recast_harness.cpp -- the real Recast library on the work bench/walkable.py measures.
//
// Built by bench/walkable.py with
//   g++ -O2 -I/usr/include/recastnavigation recast_harness.cpp -lRecast -o recast_harness
// (Debian's librecast-dev).  Reads a mesh written by the bench, runs Recast's voxel stages as
// RecastDemo's Sample_SoloMesh does (rasterise, the three span filters, compact heightfield,
// erode, distance field, regions) REPS times, and prints one JSON line with the fastest time of
// each stage and of the whole run, in milliseconds.  The eroded walkable spans of the last run go to OUT, one
// (int32 x, int32 z, float32 y) record each, y the span's floor in world units.
//
// With a tenth argument "full" it goes on as Sample_SoloMesh does to the end of Recast's build
// (contours, polygon mesh, detail mesh, RecastDemo's defaults) and also prints those stages
// and "full": the fastest whole build, what bench/import_arena.py sets a whole import against.
//
// usage: recast_harness MESH OUT cs ch max_slope_deg headroom climb radius reps [full]
// MESH: int32 nverts, int32 ntris, float32 verts[3 nverts], int32 tris[3 ntris].

#include <Recast.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

namespace {

double now_ms() {
    using clock = std::chrono::steady_clock;
    return std::chrono::duration<double, std::milli>(clock::now().time_since_epoch()).count();
}

// this process's CPU time: what a loaded machine does not inflate (the bench compares
// it with its own process time beside the wall-clock figures)
double cpu_ms() { return 1000.0 * double(std::clock()) / CLOCKS_PER_SEC; }

bool read_mesh(const char* path, std::vector<float>& verts, std::vector<int>& tris) {
    FILE* f = std::fopen(path, "rb");
    if (!f) return false;
    int nv = 0, nt = 0;
    bool ok = std::fread(&nv, 4, 1, f) == 1 && std::fread(&nt, 4, 1, f) == 1 && nv >= 0 && nt >= 0;
    if (ok) {
        verts.resize(size_t(nv) * 3);
        tris.resize(size_t(nt) * 3);
        ok = std::fread(verts.data(), 4, verts.size(), f) == verts.size() &&
             std::fread(tris.data(), 4, tris.size(), f) == tris.size();
    }
    std::fclose(f);
    return ok;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 10 && argc != 11) {
        std::fprintf(stderr, "usage: %s MESH OUT cs ch slope headroom climb radius reps [full]\n", argv[0]);
        return 2;
    }
    std::vector<float> verts;
    std::vector<int> tris;
    if (!read_mesh(argv[1], verts, tris)) {
        std::fprintf(stderr, "%s: cannot read mesh\n", argv[1]);
        return 2;
    }
    const float cs = std::atof(argv[3]), ch = std::atof(argv[4]);
    const float slope = std::atof(argv[5]);
    const int walkableHeight = int(std::ceil(std::atof(argv[6]) / ch));
    const int walkableClimb = int(std::floor(std::atof(argv[7]) / ch));
    const int walkableRadius = int(std::ceil(std::atof(argv[8]) / cs));
    const int reps = std::atoi(argv[9]);
    const bool full = argc == 11 && std::string(argv[10]) == "full";
    const int nv = int(verts.size() / 3), nt = int(tris.size() / 3);

    float bmin[3], bmax[3];
    rcCalcBounds(verts.data(), nv, bmin, bmax);
    int w = 0, h = 0;
    rcCalcGridSize(bmin, bmax, cs, &w, &h);
    // RecastDemo's defaults for the region stage
    const int minRegionArea = 8 * 8, mergeRegionArea = 20 * 20;

    // RecastDemo's defaults for the rest of the build: edges up to 12 m and 1.3 cells off,
    // six vertices a polygon, detail samples every 6 cells within one cell height
    const int maxEdgeLen = int(12.0f / cs), vertsPerPoly = 6;
    const float maxError = 1.3f, sampleDist = 6.0f * cs, sampleMaxError = 1.0f * ch;

    const char* names[] = {"rasterize", "filters", "compact", "erode", "distance", "regions", "contours",
                           "polymesh", "detail"};
    double best[9];
    double best_full = 1e30, best_cpu = 1e30, best_cpu_full = 1e30;
    for (double& b : best) b = 1e30;
    double best_total = 1e30;
    rcContext ctx(false);
    rcCompactHeightfield* keep = nullptr;
    std::vector<unsigned char> areas(nt);
    for (int r = 0; r < reps; ++r) {
        double t[7];
        const double c0 = cpu_ms();
        t[0] = now_ms();
        rcHeightfield* solid = rcAllocHeightfield();
        rcCreateHeightfield(&ctx, *solid, w, h, bmin, bmax, cs, ch);
        std::fill(areas.begin(), areas.end(), 0);
        rcMarkWalkableTriangles(&ctx, slope, verts.data(), nv, tris.data(), nt, areas.data());
        rcRasterizeTriangles(&ctx, verts.data(), nv, tris.data(), areas.data(), nt, *solid, walkableClimb);
        t[1] = now_ms();
        rcFilterLowHangingWalkableObstacles(&ctx, walkableClimb, *solid);
        rcFilterLedgeSpans(&ctx, walkableHeight, walkableClimb, *solid);
        rcFilterWalkableLowHeightSpans(&ctx, walkableHeight, *solid);
        t[2] = now_ms();
        rcCompactHeightfield* chf = rcAllocCompactHeightfield();
        rcBuildCompactHeightfield(&ctx, walkableHeight, walkableClimb, *solid, *chf);
        rcFreeHeightField(solid);
        t[3] = now_ms();
        rcErodeWalkableArea(&ctx, walkableRadius, *chf);
        t[4] = now_ms();
        rcBuildDistanceField(&ctx, *chf);
        t[5] = now_ms();
        rcBuildRegions(&ctx, *chf, 0, minRegionArea, mergeRegionArea);
        t[6] = now_ms();
        for (int k = 0; k < 6; ++k) best[k] = std::fmin(best[k], t[k + 1] - t[k]);
        best_total = std::fmin(best_total, t[6] - t[0]);
        best_cpu = std::fmin(best_cpu, cpu_ms() - c0);
        if (full) {
            double u[4];
            u[0] = now_ms();
            rcContourSet* cset = rcAllocContourSet();
            rcBuildContours(&ctx, *chf, maxError, maxEdgeLen, *cset);
            u[1] = now_ms();
            rcPolyMesh* pmesh = rcAllocPolyMesh();
            rcBuildPolyMesh(&ctx, *cset, vertsPerPoly, *pmesh);
            u[2] = now_ms();
            rcPolyMeshDetail* dmesh = rcAllocPolyMeshDetail();
            rcBuildPolyMeshDetail(&ctx, *pmesh, *chf, sampleDist, sampleMaxError, *dmesh);
            u[3] = now_ms();
            for (int k = 0; k < 3; ++k) best[6 + k] = std::fmin(best[6 + k], u[k + 1] - u[k]);
            best_full = std::fmin(best_full, u[3] - t[0]);
            best_cpu_full = std::fmin(best_cpu_full, cpu_ms() - c0);
            rcFreeContourSet(cset);
            rcFreePolyMesh(pmesh);
            rcFreePolyMeshDetail(dmesh);
        }
        if (keep) rcFreeCompactHeightfield(keep);
        keep = chf;
    }

    FILE* out = std::fopen(argv[2], "wb");
    long count = 0;
    if (out && keep) {
        for (int z = 0; z < keep->height; ++z)
            for (int x = 0; x < keep->width; ++x) {
                const rcCompactCell& c = keep->cells[x + z * keep->width];
                for (unsigned i = c.index, n = c.index + c.count; i < n; ++i) {
                    if (keep->areas[i] == RC_NULL_AREA) continue;
                    const int rec[2] = {x, z};
                    const float y = keep->bmin[1] + keep->spans[i].y * keep->ch;
                    std::fwrite(rec, 4, 2, out);
                    std::fwrite(&y, 4, 1, out);
                    ++count;
                }
            }
        std::fclose(out);
    }
    std::printf("{\"width\": %d, \"height\": %d, \"bmin\": [%g, %g, %g], \"spans\": %ld", w, h, bmin[0], bmin[1],
                bmin[2], count);
    for (int k = 0; k < (full ? 9 : 6); ++k) {
        std::printf(", \"%s\": %.4f", names[k], best[k]);
    }
    if (full) std::printf(", \"full\": %.4f, \"cpu_full\": %.4f", best_full, best_cpu_full);
    std::printf(", \"cpu_total\": %.4f", best_cpu);
    std::printf(", \"total\": %.4f}\n", best_total);
    if (keep) rcFreeCompactHeightfield(keep);
    return 0;
}
