# Counts features an independent detector (OpenCV) finds in frames written by
# `node web/cli.mjs frames`: ORB (FAST corners, multi-scale) and SIFT (blobs,
# the DoG cousin of SURF's Hessian), with OpenCV's default settings.
import cv2, json, sys, statistics
d = sys.argv[1]
idx = json.load(open(f"{d}/index.json"))
orb = cv2.ORB_create(nfeatures=5000)
sift = cv2.SIFT_create()
o, s = [], []
for f in idx["frames"]:
    img = cv2.imread(f"{d}/{f['file']}", cv2.IMREAD_GRAYSCALE)
    o.append(len(orb.detect(img, None)))
    s.append(len(sift.detect(img, None)))
q = lambda v: (min(v), statistics.quantiles(v, n=10)[0], statistics.median(v), max(v))
print(f"{len(o)} frames; ORB (min, 10th pct, median, max): {q(o)}; SIFT: {q(s)}")
print("frames with fewer than 100 SIFT keypoints:", sum(1 for x in s if x < 100))
