// Reference SURF for the quality comparison in BENCHMARKS.md ("SURF"; the
// history: docs/history/issue-4-surf.md): runs dlib's get_surf_points (Debian's libdlib-dev, dlib 19.24) on
// a binary PGM and prints one keypoint per line:
//
//   x y scale angle laplacian d0 ... d63
//
// Usage: dlib_surf IMAGE.pgm MAX_POINTS [THRESHOLD]
// Built and driven by tests/surf_reference.rs (an ignored test); not part of
// the project's build.
#include <dlib/image_keypoint.h>
#include <dlib/array2d.h>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

static bool read_token(std::istream& in, std::string& tok) {
    tok.clear();
    int c;
    while ((c = in.get()) != EOF) {
        if (c == '#') {
            while ((c = in.get()) != EOF && c != '\n') {}
            continue;
        }
        if (std::isspace(c)) {
            if (!tok.empty()) return true;
            continue;
        }
        tok.push_back(static_cast<char>(c));
    }
    return !tok.empty();
}

int main(int argc, char** argv) {
    if (argc < 3) {
        std::cerr << "usage: dlib_surf IMAGE.pgm MAX_POINTS [THRESHOLD]\n";
        return 2;
    }
    std::ifstream in(argv[1], std::ios::binary);
    std::string magic, w, h, maxv;
    if (!read_token(in, magic) || magic != "P5" || !read_token(in, w) || !read_token(in, h) ||
        !read_token(in, maxv) || maxv != "255") {
        std::cerr << argv[1] << ": not an 8-bit binary PGM\n";
        return 1;
    }
    const long cols = std::stol(w), rows = std::stol(h);
    dlib::array2d<unsigned char> img(rows, cols);
    for (long r = 0; r < rows; ++r)
        for (long c = 0; c < cols; ++c) {
            int v = in.get();
            if (v == EOF) {
                std::cerr << argv[1] << ": truncated\n";
                return 1;
            }
            img[r][c] = static_cast<unsigned char>(v);
        }
    const long max_points = std::stol(argv[2]);
    const double threshold = argc > 3 ? std::stod(argv[3]) : 30.0;
    const auto points = dlib::get_surf_points(img, max_points, threshold);
    for (const auto& sp : points) {
        std::printf("%.4f %.4f %.4f %.6f %.0f", sp.p.center.x(), sp.p.center.y(), sp.p.scale,
                    sp.angle, sp.p.laplacian);
        for (long i = 0; i < 64; ++i) std::printf(" %.7f", sp.des(i));
        std::printf("\n");
    }
    return 0;
}
