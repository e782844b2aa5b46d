// NumPy .npy files (little-endian float32, C order) and their JSON sidecars for density and lighting grids.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/grid/grid.h"

namespace sylva {

// An n-dimensional float32 array in C order (last index fastest); data.size() == product(shape).
struct NpyArray {
    std::vector<size_t> shape;
    std::vector<float> data;
};

// Reads a .npy file (format version 1.0, 2.0 or 3.0 header) holding little-endian float32 ('<f4') in
// C order. Throws Error naming the file and the problem: not an npy file, truncated, another dtype
// (named, with "float32 is required"), fortran_order True, a zero-sized or overflowing shape, a shape
// that needs more bytes than the file holds, a malformed header dictionary.
NpyArray readNpy(const std::string& path);

// Writes a .npy file exactly as NumPy does: header "{'descr': '<f4', 'fortran_order': False,
// 'shape': (...), }" padded with spaces and a final '\n' so the data starts at a multiple of 64
// bytes (version 1.0; 2.0 only for headers over 64 KiB). Atomic: temporary file, then rename.
// Throws Error naming the file when data.size() != product(shape) or the file cannot be written.
void writeNpy(const std::string& path, const NpyArray& array);

// Sidecar of a grid file: PATH + ".json" (e.g. "tree.npy.json").
std::string gridSidecarPath(const std::string& npyPath);
// Wood fraction file next to a density file: "tree.npy" -> "tree.wood.npy" (PATH + ".wood.npy" when
// PATH does not end in ".npy").
std::string woodFractionPath(const std::string& densityNpyPath);

// Writes the density as shape (X,Y,Z) to PATH, the wood fraction (same shape) to
// woodFractionPath(PATH), and the sidecar PATH.json:
//   {"version": 1, "kind": "density", "dims": [X,Y,Z], "origin": [x,y,z], "spacing": s,
//    "wood": "NAME.wood.npy"}
// Every file is written atomically. Throws Error naming the file.
void writeDensityGrid(const std::string& path, const DensityGrid& grid);

// Reads a density grid written by writeDensityGrid or any (X,Y,Z) float32 .npy. The sidecar, when
// present, gives origin and spacing (else origin 0, spacing 1) and must agree on kind and dims; the
// wood fraction file, when present, must have the same shape (else zeros). Throws Error naming the file.
DensityGrid readDensityGrid(const std::string& path);

// Writes RGB lighting as shape (X,Y,Z,3) plus the sidecar PATH.json with kind "lighting". A non-empty
// extraJson must be a JSON object (e.g. the LB parameters); it is stored as the sidecar's "parameters".
void writeLightingGrid(const std::string& path, const LightingGrid& grid, const std::string& extraJson = {});

// Reads a lighting grid: shape (X,Y,Z,3), sidecar optional as for readDensityGrid.
LightingGrid readLightingGrid(const std::string& path);

} // namespace sylva
