// veil — the checks io/vdb.cpp makes on an OpenVDB file before OpenVDB
// reads it (C++, internal): OpenVDB takes lengths, counts and sizes from the
// stream as they come, so a truncated or corrupt file made it allocate
// gigabytes before failing. The header, the file's metadata, the grid
// descriptors, each grid's own header and the trees of the grids to be read
// are walked and every claim checked against the file's size (and the
// grid's block); io/vdb_header.cpp has the layout.
#ifndef VEIL_VDB_HEADER_HPP
#define VEIL_VDB_HEADER_HPP

#include <string>

// true when nothing is amiss (or the file is not OpenVDB's: OpenVDB then
// says so itself); false with *why ("truncated or corrupt OpenVDB file:
// ..."). Files older than version 222 (OpenVDB 2.0) and files without
// grid offsets (written by io::Stream) are refused.
bool veil__vdb_header_ok(const std::string& path, std::string* why);

// The same, and the tree of every grid named `grid` (the name as OpenVDB's
// File::readGrid takes it; an instance's parent's tree for an instance):
// every node count, mask and compressed chunk checked, so that OpenVDB
// allocates nothing the file does not hold. false with *why also for a tree
// type the walk does not know (not one of float, double, int32, int64,
// vec3s, vec3d, vec3i or bool on OpenVDB's 5-4-3 layout).
bool veil__vdb_tree_ok(const std::string& path, const std::string& grid, std::string* why);

#endif
