// MuJoCo's side of the peer benchmark (bench/peers/peers.py builds and runs it): one model, one
// integrator, a list of timesteps. For each timestep: reset to keyframe 0, step for DURATION
// seconds, and after every SAMPLE seconds compute the kinematics and copy the hand site's world
// position; time the whole loop (mj_step + mj_kinematics + the copy, nothing else) and keep the
// best of REPEATS. Written in C so that no Python call overhead is timed.
//
// usage: mj_ladder MODEL.xml INTEGRATOR DURATION SAMPLE REPEATS SITE OUT.bin DT [DT ...]
//   INTEGRATOR: euler | rk4 | implicit | implicitfast
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
  for (int a = 8; a < argc; a++) {
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
        for (long i = 0; i < k; i++) mj_step(m, d);
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
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
