#include "io/svg_writer.hpp"

#include <cstdio>
#include <iomanip>

namespace angiosynth {

void writeSvg(std::ostream& o, const Forest& forest, const GrowthDomain& d) {
  const VascularTree& t = forest.vessels;
  const Vec3 hi = d.hi();
  o << std::setprecision(9);
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << hi.x << "mm\" height=\"" << hi.y << "mm\" viewBox=\"0 0 " << hi.x << ' ' << hi.y
    << "\">\n"
    << "<title>angiosynth CCO tree, " << t.totalTerminals() << " terminals, lengths in mm</title>\n"
    << "<g transform=\"matrix(1 0 0 -1 0 " << hi.y << ")\">\n";
  const Vec3 c = d.center();
  switch (d.shape()) {
    case DomainShape::Disc:
      o << "<circle cx=\"" << c.x << "\" cy=\"" << c.y << "\" r=\"" << d.size() << "\" fill=\"#f4f1ea\" stroke=\"#b0a898\" stroke-width=\""
        << d.size() / 400 << "\"/>\n";
      break;
    case DomainShape::Square:
      o << "<rect x=\"" << c.x - d.size() << "\" y=\"" << c.y - d.size() << "\" width=\"" << 2 * d.size() << "\" height=\"" << 2 * d.size()
        << "\" fill=\"#f4f1ea\" stroke=\"#b0a898\" stroke-width=\"" << d.size() / 400 << "\"/>\n";
      break;
    default: {
      const auto& m = d.frame();
      o << "<g fill=\"#f4f1ea\">\n";
      for (int j = 0; j < m.dims[1]; ++j)
        for (int i = 0; i < m.dims[0];) {
          if (!(m.demand[m.flat(i, j, 0)] > 0)) {
            ++i;
            continue;
          }
          int run = i;
          while (run < m.dims[0] && m.demand[m.flat(run, j, 0)] > 0) ++run;
          o << "<rect x=\"" << i * m.voxel_mm << "\" y=\"" << j * m.voxel_mm << "\" width=\"" << (run - i) * m.voxel_mm << "\" height=\""
            << m.voxel_mm << "\"/>\n";
          i = run;
        }
      o << "</g>\n";
    }
  }
  const auto order = t.topDownOrder();
  for (std::size_t k = 0; k < order.size(); ++k) {
    const auto i = order[k];
    if (t.isRoot(i)) {  // a tree's nodes follow its root in top-down order
      if (k > 0) o << "</g>\n";
      char colour[8];
      std::snprintf(colour, sizeof colour, "%06x", unsigned(classColour(forest.trees.at(t.tree[i]).class_label)));
      o << "<g stroke=\"#" << colour << "\" stroke-linecap=\"round\" fill=\"none\">\n";
      continue;
    }
    const Vec3& a = t.position[t.parent[i]];
    const Vec3& b = t.position[i];
    o << "<line x1=\"" << a.x << "\" y1=\"" << a.y << "\" x2=\"" << b.x << "\" y2=\"" << b.y << "\" stroke-width=\"" << 2 * t.radius[i] << "\"/>\n";
  }
  o << "</g>\n</g>\n</svg>\n";
}

}  // namespace angiosynth
