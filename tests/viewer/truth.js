// The odometry a viewer client received (ws_client_test.js: odometry.csv, stamps on the
// robot's CLOCK_MONOTONIC) against the simulated truth (semap-onboard --report: truth.csv, the
// truth in the map frame on the IMU's 5 ms grid), interpolated at each stamp; the filter's
// first 10 s are left out, as the run's own "pose vs truth" figure does.
//
//   node truth.js ODOMETRY.csv TRUTH.csv MAX_RMSE_M
'use strict';
const fs = require('fs');
const { check, log } = require('./lib.js');

const [odomPath, truthPath, maxRmse] = process.argv.slice(2);
const rows = (p) => fs.readFileSync(p, 'utf8').trim().split('\n').slice(1).map((l) => l.split(',').map(Number));
const odom = rows(odomPath);
const truth = rows(truthPath);
check(truth.length > 100 && odom.length > 100, 'truth ' + truth.length + ' rows, odometry ' + odom.length);

let j = 0, sum = 0, n = 0, max = 0, travelled = 0;
const first = odom[0][0];
for (let i = 0; i < odom.length; ++i) {
  const [t, x, y, z] = odom[i];
  if (i > 0) travelled += Math.hypot(x - odom[i - 1][1], y - odom[i - 1][2]);
  if (t - first < 10) continue;
  while (j + 1 < truth.length && truth[j + 1][0] < t) ++j;
  if (j + 1 >= truth.length || truth[j][0] > t) continue;
  const [t0, x0, y0, z0] = truth[j], [t1, x1, y1, z1] = truth[j + 1];
  const f = (t - t0) / (t1 - t0);
  if (t1 - t0 > 0.1) continue; // a gap in the truth
  const e = Math.hypot(x - (x0 + f * (x1 - x0)), y - (y0 + f * (y1 - y0)), z - (z0 + f * (z1 - z0)));
  sum += e * e;
  max = Math.max(max, e);
  ++n;
}
check(n >= 100, 'only ' + n + ' odometry messages fall within the truth (clock offset?)');
const rmse = Math.sqrt(sum / n);
log('odometry vs truth: RMSE ' + rmse.toFixed(3) + ' m, max ' + max.toFixed(3) + ' m over ' + n +
  ' messages; the robot drove ' + travelled.toFixed(1) + ' m');
check(travelled > 20, 'the pose moved only ' + travelled.toFixed(1) + ' m');
check(rmse <= Number(maxRmse), 'odometry RMSE ' + rmse.toFixed(3) + ' m > ' + maxRmse + ' m');
log('PASS');
