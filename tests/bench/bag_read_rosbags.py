"""How fast the Python `rosbags` library reads a ROS 1 bag and decodes its
LaserScan and Odometry messages: the side-by-side figure for
tests/bench/bag_read.mjs (BENCHMARKS.md). Every chunk is read and
decompressed, every sensor_msgs/LaserScan and nav_msgs/Odometry message
deserialised into its Python object. Several runs in one process; prints
each run and the minimum and median.

    python3 tests/bench/bag_read_rosbags.py [BAG] [--runs N]

BAG defaults to bags/freiburg/intel.bag under ../shared/data (or
$SLAMLAB_DATA). Needs `pip install rosbags`.
"""

import os
import sys
import time
from pathlib import Path

from rosbags.rosbag1 import Reader
from rosbags.typesys import Stores, get_typestore

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("SLAMLAB_DATA", ROOT.parent / "shared" / "data"))
DECODED = {"sensor_msgs/msg/LaserScan", "nav_msgs/msg/Odometry"}


def read(bag: Path, typestore) -> int:
    """Reads `bag`, deserialising every LaserScan and Odometry; returns how many."""
    n = 0
    with Reader(bag) as reader:
        wanted = [c for c in reader.connections if c.msgtype in DECODED]
        for conn, _t, raw in reader.messages(connections=wanted):
            typestore.deserialize_ros1(raw, conn.msgtype)
            n += 1
    return n


def main() -> None:
    args = sys.argv[1:]
    runs = 5
    bag = DATA / "bags" / "freiburg" / "intel.bag"
    i = 0
    while i < len(args):
        if args[i] == "--runs":
            runs = int(args[i + 1])
            i += 1
        else:
            bag = Path(args[i])
        i += 1
    typestore = get_typestore(Stores.ROS1_NOETIC)
    times = []
    n = 0
    for k in range(runs):
        t0 = time.perf_counter()
        n = read(bag, typestore)
        dt = (time.perf_counter() - t0) * 1000
        times.append(dt)
        print(f"run {k + 1}: {dt:.0f} ms ({n} LaserScan + Odometry)")
    times.sort()
    print(
        f"{bag.name}: rosbags in Python: {n} LaserScan + Odometry messages decoded; "
        f"min {times[0]:.0f} ms, median {times[len(times) // 2]:.0f} ms over {runs} runs"
    )


if __name__ == "__main__":
    main()
