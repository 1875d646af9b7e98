// A room whose round wall is traced as many short unnamed segments, the way
// a floor plan digitised from a drawing arrives: the stress case for wall
// textures in docs/history/issue-2-3-simulation-and-camera.md ("A traced room"). Writes scenario JSON to
// stdout.
//
//   node tests/bench/traced_room.mjs [SEGMENTS] > /tmp/traced.json
//   node web/cli.mjs run /tmp/traced.json --json
//
// A circle of radius 15 m cut into SEGMENTS walls (default 4000, 2.4 cm
// each), a 10 m square block in the middle, two robots between them.
const n = Number(process.argv[2] ?? 4000);
if (!Number.isInteger(n) || n < 8 || n > 9996) {
  console.error('SEGMENTS: an integer from 8 to 9996');
  process.exit(2);
}
const r = 15;
const round = (v) => Math.round(v * 1e6) / 1e6;
const at = (i) => {
  const a = (2 * Math.PI * i) / n;
  return [round(r * Math.cos(a)), round(r * Math.sin(a))];
};
const walls = [];
for (let i = 0; i < n; i++) walls.push({ from: at(i), to: at(i + 1) });
const block = [[-5, -5], [5, -5], [5, 5], [-5, 5]];
for (let i = 0; i < 4; i++) walls.push({ from: block[i], to: block[(i + 1) % 4] });
const scenario = {
  name: `traced-room-${n}`,
  seed: 1,
  duration_s: 120,
  walls,
  robots: [
    { name: 'a', start: [-10, 0, 0.3], follow: 'left' },
    { name: 'b', start: [10, 3, 2.0], follow: 'right', distance: 0.8 },
  ],
};
process.stdout.write(JSON.stringify(scenario) + '\n');
