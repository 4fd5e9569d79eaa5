#pragma once
// The pictures of reports and studies, drawn by postprocess/plots.py (matplotlib) from the data
// files diefill writes beside them.
#include <string>
#include <vector>

namespace pipeline {

// Runs plots.py with `arguments` (a kind of picture, then its data); warns, never fails, when
// Python or matplotlib is missing.
void draw_pictures(const std::vector<std::string>& arguments);

}  // namespace pipeline
