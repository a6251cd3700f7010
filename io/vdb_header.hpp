// veil — the checks io/vdb.cpp makes on an OpenVDB file before OpenVDB
// reads it (C++, internal): OpenVDB takes lengths, counts and sizes from the
// stream as they come, so a truncated or corrupt file made it allocate
// gigabytes before failing. The header, the file's metadata, the grid
// descriptors and each grid's own header are walked and every claim checked
// against the file's size (and the grid's block); io/vdb_header.cpp has the
// layout.
#ifndef VEIL_VDB_HEADER_HPP
#define VEIL_VDB_HEADER_HPP

#include <string>

// true when nothing is amiss (or the file is not one this walk knows: not
// OpenVDB, or older than file version 218: OpenVDB then says so itself);
// false with *why ("truncated or corrupt OpenVDB file: ...").
bool veil__vdb_header_ok(const std::string& path, std::string* why);

#endif
