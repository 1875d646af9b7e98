// Reference SURF for the quality comparison in BENCHMARKS.md ("SURF"; how
// it is built: docs/history/issue-4-surf.md): runs OpenCV's
// cv::xfeatures2d::SURF (the non-free contrib module, built from source
// with OPENCV_ENABLE_NONFREE) on a binary PGM and prints one keypoint per
// line, as dlib_surf.cpp does:
//
//   x y size angle laplacian d0 ... d63
//
// `size` is OpenCV's KeyPoint::size and `angle` its degrees, printed raw;
// tests/surf_reference.rs converts them. Default settings (4 octaves, 3
// layers each, 64-d, with orientation); the threshold is lowered until there
// are MAX_POINTS keypoints and the strongest MAX_POINTS are kept.
//
// Usage: opencv_surf IMAGE.pgm MAX_POINTS [TIMING_RUNS]
// With TIMING_RUNS > 0 it prints instead the median and minimum time (ms) of
// that many detect + describe runs at the default threshold (100).
// Built and driven by tests/surf_reference.rs (an ignored test); not part of
// the project's build.
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/xfeatures2d/nonfree.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <vector>

int main(int argc, char** argv) {
    if (argc < 3) {
        std::cerr << "usage: opencv_surf IMAGE.pgm MAX_POINTS [TIMING_RUNS]\n";
        return 2;
    }
    cv::Mat img = cv::imread(argv[1], cv::IMREAD_GRAYSCALE);
    if (img.empty()) {
        std::cerr << argv[1] << ": cannot read\n";
        return 1;
    }
    const size_t max_points = std::stoul(argv[2]);
    const int runs = argc > 3 ? std::stoi(argv[3]) : 0;
    if (runs > 0) {
        cv::setNumThreads(1);
        auto surf = cv::xfeatures2d::SURF::create();
        std::vector<double> ms;
        size_t n = 0;
        for (int r = 0; r < runs; ++r) {
            std::vector<cv::KeyPoint> kps;
            cv::Mat desc;
            const auto t0 = std::chrono::steady_clock::now();
            surf->detectAndCompute(img, cv::noArray(), kps, desc);
            const auto t1 = std::chrono::steady_clock::now();
            ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            n = kps.size();
        }
        std::sort(ms.begin(), ms.end());
        std::printf("keypoints %zu median_ms %.3f min_ms %.3f\n", n, ms[ms.size() / 2], ms[0]);
        return 0;
    }
    std::vector<cv::KeyPoint> kps;
    for (double threshold = 100.0; threshold >= 1.0; threshold /= 2.0) {
        kps.clear();
        cv::xfeatures2d::SURF::create(threshold)->detect(img, kps);
        if (kps.size() >= max_points) break;
    }
    cv::KeyPointsFilter::retainBest(kps, static_cast<int>(max_points));
    cv::Mat desc;
    cv::xfeatures2d::SURF::create()->compute(img, kps, desc);
    for (int i = 0; i < desc.rows; ++i) {
        const cv::KeyPoint& k = kps[i];
        std::printf("%.4f %.4f %.4f %.4f %d", k.pt.x, k.pt.y, k.size, k.angle, k.class_id);
        for (int j = 0; j < desc.cols; ++j) std::printf(" %.7f", desc.at<float>(i, j));
        std::printf("\n");
    }
    return 0;
}
