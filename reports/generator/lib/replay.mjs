// A run's trajectory.csv and contacts.csv as a replay's data file carries them: the same lines and
// fields, each number written as the shortest text that gives the viewer the very value it keeps
// (viewer/src/data.js: float64 for times, poses and the contact force's parts, float32 for velocities
// and contact points). polydyn writes %.17g ("0.55000000000000004"); JavaScript's shortest round trip is
// "0.55". The arrays the viewer builds are identical to the bit; the Gedanken suite's runs shrink by a
// fifth. A field that is not a plain finite number is left as it is, for the viewer to report.

// the text as polydyn would accept it (no spaces, not empty), or null
function plainNumber(field) {
  if (field === '' || field.trim() !== field) return null;
  const x = Number(field);
  return Number.isFinite(x) ? x : null;
}

// shortest text of the same double
export function shortDouble(field) {
  const x = plainNumber(field);
  if (x === null) return field;
  return Object.is(x, -0) ? '-0' : String(x);
}

// shortest text of the same float32 (at most 9 significant digits)
export function shortFloat32(field) {
  const x = plainNumber(field);
  if (x === null) return field;
  const f = Math.fround(x);
  if (Object.is(f, -0)) return '-0';
  for (let digits = 1; digits < 9; ++digits) {
    const y = Number(f.toPrecision(digits));
    if (Math.fround(y) === f) return String(y);
  }
  return String(Number(f.toPrecision(9)));
}

const same = (field) => field;
// trajectory.csv: t,body,x,y,z,qw,qx,qy,qz (float64) vx,vy,vz,wx,wy,wz (float32)
const TRAJECTORY = [shortDouble, same, ...Array(7).fill(shortDouble), ...Array(6).fill(shortFloat32)];
// contacts.csv: t,body_a,body_b,kind,feat_a,feat_b, px,py,pz (float32), nx,ny,nz,fn,ftx,fty,ftz (float64: the
// force fn n + ft is formed in float64), mode
const CONTACTS = [shortDouble, same, same, same, same, same, ...Array(3).fill(shortFloat32), ...Array(7).fill(shortDouble), same];

function compact(text, columns) {
  if (text === null) return null;
  const lines = text.split('\n');
  for (let i = 1; i < lines.length; ++i) {
    if (lines[i].includes('"')) continue;  // quoted names: left as they are (polydyn writes none)
    lines[i] = lines[i].split(',').map((f, k) => (columns[k] || same)(f)).join(',');
  }
  return lines.join('\n');
}

export const compactTrajectory = (text) => compact(text, TRAJECTORY);
export const compactContacts = (text) => compact(text, CONTACTS);
