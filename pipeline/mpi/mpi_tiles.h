// The tiles `sylva render --mpi` cuts a band of rows into, in queue order (header-only, no MPI: the load
// balance benchmark simulates the same list).
#pragma once

#include <algorithm>
#include <vector>

namespace sylva::mpi {

struct TileRect {
    int x0, y0, x1, y1;
};

// Rows [y0, y1) of a frame `width` wide: tiles of `edge` pixels (halved down to 8 while there are fewer
// than 4 per rank), left to right, top to bottom; with more than one rank the last 2 per rank are cut
// into quarters (down to 8 pixels), so the queue ends with small tiles and no rank is left with a dear
// tile while the others wait.
inline std::vector<TileRect> frameTiles(int width, int y0, int y1, int ranks, int edge)
{
    edge = std::max(1, edge);
    auto tilesAt = [&](int e) { return ((width + e - 1) / e) * ((y1 - y0 + e - 1) / e); };
    while (edge > 8 && tilesAt(edge) < 4 * ranks) edge /= 2;
    std::vector<TileRect> tiles;
    for (int ty = y0; ty < y1; ty += edge)
        for (int tx = 0; tx < width; tx += edge) tiles.push_back({tx, ty, std::min(tx + edge, width), std::min(ty + edge, y1)});
    const int half = edge / 2;
    if (ranks < 2 || half < 8) return tiles;
    const size_t tail = std::min(tiles.size() / 4, size_t(2 * ranks));
    std::vector<TileRect> out(tiles.begin(), tiles.end() - std::ptrdiff_t(tail));
    for (size_t i = tiles.size() - tail; i < tiles.size(); ++i) {
        const TileRect t = tiles[i];
        for (int y = t.y0; y < t.y1; y += half)
            for (int x = t.x0; x < t.x1; x += half) out.push_back({x, y, std::min(x + half, t.x1), std::min(y + half, t.y1)});
    }
    return out;
}

} // namespace sylva::mpi
