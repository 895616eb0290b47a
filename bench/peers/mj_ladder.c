// MuJoCo's side of the peer benchmark (bench/peers/peers.py builds and runs it): one model, one
// integrator, a list of timesteps. For each timestep: reset to keyframe 0, step for DURATION
// seconds, and after every SAMPLE seconds compute the kinematics and copy the hand site's world
// position; time the whole loop (mj_step + mj_kinematics + the copy, nothing else) and keep the
// best of REPEATS. Written in C so that no Python call overhead is timed.
//
// usage: mj_ladder MODEL.xml INTEGRATOR DURATION SAMPLE REPEATS SITE OUT.bin [--ctrl=U.bin] DT [DT ...]
//   INTEGRATOR: euler | rk4 | implicit | implicitfast
//   --ctrl=U.bin: a time-varying control (the contact scene tracks the circle): int64 n, int64 nu,
//     float64 dt, then n x nu float64 u(k dt). Before every mj_step, ctrl = u at the step's
//     midpoint, by 4-point Lagrange interpolation on the grid (exact for cubics; with dt = 1 ms
//     its error is ~1e-13 rad here, far below any error measured). The midpoint keeps the
//     sampling of a smooth control second-order in the timestep (one value per step: MuJoCo
//     holds ctrl over a step, over RK4's four stages too). The interpolation is timed with the
//     step: it is what a user's controller costs, and it is cheap next to mj_step.
// stdout: one line per DT, "dt wall_s nsamples steps_per_sample finite(0/1)"; finite is 0 when a
// sample is not finite or MuJoCo flagged a bad qacc/qvel/qpos (it then resets the state).
// OUT.bin: for each DT in order, nsamples x 3 float64 (the hand path, samples at 0, SAMPLE, ...).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

typedef struct {
  long n, nu;
  double dt;
  double* u;
} Ctrl;

// u(t) by 4-point Lagrange interpolation on the uniform grid (clamped to the table's ends)
static void ctrl_at(const Ctrl* c, double t, double* out) {
  double x = t / c->dt;
  long k = (long)floor(x) - 1;  // nodes k, k+1, k+2, k+3 around x
  if (k < 0) k = 0;
  if (k > c->n - 4) k = c->n - 4;
  double s = x - k;  // in [0, 3] inside the table
  double w0 = -(s - 1) * (s - 2) * (s - 3) / 6.0, w1 = s * (s - 2) * (s - 3) / 2.0;
  double w2 = -s * (s - 1) * (s - 3) / 2.0, w3 = s * (s - 1) * (s - 2) / 6.0;
  const double* u = c->u + k * c->nu;
  for (long j = 0; j < c->nu; j++) {
    out[j] = w0 * u[j] + w1 * u[c->nu + j] + w2 * u[2 * c->nu + j] + w3 * u[3 * c->nu + j];
  }
}

static int die(const char* msg, const char* arg) {
  fprintf(stderr, "mj_ladder: %s%s\n", msg, arg ? arg : "");
  return 2;
}

int main(int argc, char** argv) {
  if (argc < 9) {
    return die("usage: mj_ladder MODEL.xml INTEGRATOR DURATION SAMPLE REPEATS SITE OUT.bin DT [DT ...]", NULL);
  }
  char err[1000] = "";
  mjModel* m = mj_loadXML(argv[1], NULL, err, sizeof(err));
  if (!m) return die("cannot load the model: ", err);
  int integrator;
  if (!strcmp(argv[2], "euler")) integrator = mjINT_EULER;
  else if (!strcmp(argv[2], "rk4")) integrator = mjINT_RK4;
  else if (!strcmp(argv[2], "implicit")) integrator = mjINT_IMPLICIT;
  else if (!strcmp(argv[2], "implicitfast")) integrator = mjINT_IMPLICITFAST;
  else return die("unknown integrator: ", argv[2]);
  double duration = atof(argv[3]), sample = atof(argv[4]);
  int repeats = atoi(argv[5]);
  if (!(duration > 0) || !(sample > 0) || repeats < 1) return die("DURATION, SAMPLE and REPEATS must be positive", NULL);
  int site = mj_name2id(m, mjOBJ_SITE, argv[6]);
  if (site < 0) return die("no site named ", argv[6]);
  if (m->nkey < 1) return die("the model needs a keyframe (the initial state)", NULL);
  FILE* out = fopen(argv[7], "wb");
  if (!out) return die("cannot write ", argv[7]);
  long nsamples = lround(duration / sample) + 1;
  double* hand = malloc(sizeof(double) * 3 * nsamples);
  mjData* d = mj_makeData(m);
  m->opt.integrator = integrator;
  int first_dt = 8;
  Ctrl ctrl = {0, 0, 0.0, NULL};
  if (!strncmp(argv[8], "--ctrl=", 7)) {
    first_dt = 9;
    FILE* f = fopen(argv[8] + 7, "rb");
    if (!f) return die("cannot read ", argv[8] + 7);
    long long head[2];
    if (fread(head, sizeof(long long), 2, f) != 2 || fread(&ctrl.dt, sizeof(double), 1, f) != 1) return die("short control file ", argv[8] + 7);
    ctrl.n = head[0];
    ctrl.nu = head[1];
    if (ctrl.n < 4 || ctrl.nu != m->nu || !(ctrl.dt > 0)) return die("the control file does not fit the model: ", argv[8] + 7);
    ctrl.u = malloc(sizeof(double) * ctrl.n * ctrl.nu);
    if (fread(ctrl.u, sizeof(double), ctrl.n * ctrl.nu, f) != (size_t)(ctrl.n * ctrl.nu)) return die("short control file ", argv[8] + 7);
    fclose(f);
  }
  for (int a = first_dt; a < argc; a++) {
    double dt = atof(argv[a]);
    long k = lround(sample / dt);
    if (!(dt > 0) || k < 1 || fabs(k * dt - sample) > 1e-12 * sample) {
      fclose(out);
      return die("every DT must divide SAMPLE: ", argv[a]);
    }
    m->opt.timestep = dt;
    double best = INFINITY;
    int finite = 1;
    for (int r = 0; r < repeats; r++) {
      mj_resetDataKeyframe(m, d, 0);
      double t0 = now();
      mj_kinematics(m, d);
      memcpy(hand, d->site_xpos + 3 * site, sizeof(double) * 3);
      for (long s = 1; s < nsamples; s++) {
        for (long i = 0; i < k; i++) {
          if (ctrl.u) ctrl_at(&ctrl, d->time + 0.5 * dt, d->ctrl);
          mj_step(m, d);
        }
        mj_kinematics(m, d);
        memcpy(hand + 3 * s, d->site_xpos + 3 * site, sizeof(double) * 3);
      }
      double wall = now() - t0;
      if (wall < best) best = wall;
      // on a non-finite or huge state MuJoCo warns and resets the data (and goes on): count it
      if (d->warning[mjWARN_BADQACC].number || d->warning[mjWARN_BADQVEL].number || d->warning[mjWARN_BADQPOS].number) finite = 0;
      for (long s = 0; s < 3 * nsamples; s++) {
        if (!isfinite(hand[s])) { finite = 0; break; }
      }
      if (!finite) break;  // a diverged run is not timed again
    }
    fwrite(hand, sizeof(double), 3 * nsamples, out);
    printf("%.9g %.9g %ld %ld %d\n", dt, best, nsamples, k, finite);
    fflush(stdout);
  }
  fclose(out);
  free(hand);
  free(ctrl.u);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
