// Times MuJoCo's forward dynamics (mj_forward) on a fixed-base model, for
// the Pinocchio comparison (README.md here). run.py passes a URDF copy with
// the <visual> and <collision> elements removed (MuJoCo would look for the
// meshes) and, for the Panda, the finger joints made fixed.
//
//   mujoco_bench MODEL --joints J1,J2,... [--name NAME] [--batch B]
//                [--reps R] [--seed S]
//
// The states are drawn as pinocchio_bench.cpp draws them (SplitMix64, per
// state q_i uniform in [-pi, pi), then v_i, then tau_i uniform in [-1, 1),
// in the order of --joints, which is Pinocchio's) and put into qpos, qvel
// and qfrc_applied by joint name. Everything that would make MuJoCo's
// answer differ from the rigid-body dynamics of ABA is switched off: the
// constraint solver (joint limits, contacts, equalities), springs,
// dampers and armature. mj_forward then computes qacc = M^-1 (tau - bias).
// Output: the JSON lines of the other drivers.

#define _POSIX_C_SOURCE 200809L // clock_gettime and strdup under -std=c11

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

static uint64_t rng_state;

static uint64_t splitmix64(void)
{
  uint64_t z = (rng_state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

static double uniform(double lo, double hi)
{
  double u = (double)(splitmix64() >> 11) * 0x1.0p-53;
  return lo + (hi - lo) * u;
}

static void usage(const char *why)
{
  fprintf(stderr, "mujoco_bench: %s\n", why);
  fprintf(stderr, "usage: mujoco_bench MODEL --joints J1,J2 [--name NAME] [--batch B] "
                  "[--reps R] [--seed S]\n");
  exit(2);
}

static double now_ns(void)
{
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

static int compare(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

volatile double sink;

int main(int argc, char **argv)
{
  if (argc < 2)
    usage("no model given");
  const char *path = argv[1], *name = argv[1];
  char *joints = NULL;
  int count = 1000, reps = 31;
  uint64_t seed = 20240917;
  for (int i = 2; i < argc; ++i)
  {
    if (i + 1 >= argc)
      usage("an option without a value");
    const char *arg = argv[i], *value = argv[++i];
    if (!strcmp(arg, "--joints"))
      joints = strdup(value);
    else if (!strcmp(arg, "--name"))
      name = value;
    else if (!strcmp(arg, "--batch"))
      count = atoi(value);
    else if (!strcmp(arg, "--reps"))
      reps = atoi(value);
    else if (!strcmp(arg, "--seed"))
      seed = strtoull(value, NULL, 10);
    else
      usage("unknown option");
  }
  if (!joints)
    usage("--joints is required");
  if (count < 1 || reps < 1)
    usage("--batch and --reps must be positive");

  char error[1000] = "";
  mjModel *m = mj_loadXML(path, NULL, error, sizeof error);
  if (!m)
  {
    fprintf(stderr, "mujoco_bench: cannot load %s: %s\n", path, error);
    return 1;
  }
  m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_EQUALITY | mjDSBL_FRICTIONLOSS |
                         mjDSBL_LIMIT | mjDSBL_CONTACT | mjDSBL_SPRING | mjDSBL_DAMPER |
                         mjDSBL_ACTUATION | mjDSBL_SENSOR;
  for (int i = 0; i < m->nv; ++i)
  {
    m->dof_damping[i] = 0;
    m->dof_armature[i] = 0;
    m->dof_frictionloss[i] = 0;
  }
  mjData *d = mj_makeData(m);

  // Joint addresses in the order of --joints.
  int n = 0;
  int *qadr = malloc(sizeof(int) * (size_t)m->njnt), *vadr = malloc(sizeof(int) * (size_t)m->njnt);
  printf("{\"impl\":\"mujoco\",\"version\":\"%s\",\"model\":\"%s\",\"nv\":%d,\"joints\":[",
         mj_versionString(), name, m->nv);
  for (char *tok = strtok(joints, ","); tok; tok = strtok(NULL, ","))
  {
    int id = mj_name2id(m, mjOBJ_JOINT, tok);
    if (id < 0 || n >= m->njnt)
      usage("a joint of --joints is not in the model");
    if (m->jnt_type[id] != mjJNT_HINGE)
      usage("a joint of --joints is not a hinge");
    qadr[n] = m->jnt_qposadr[id];
    vadr[n] = m->jnt_dofadr[id];
    printf("%s\"%s\"", n ? "," : "", tok);
    ++n;
  }
  printf("],\"gravity\":[%g,%g,%g]}\n", m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]);
  if (n != m->nq || n != m->nv)
    usage("--joints must name every joint of the model");

  double *q = malloc(sizeof(double) * (size_t)(count * n));
  double *v = malloc(sizeof(double) * (size_t)(count * n));
  double *tau = malloc(sizeof(double) * (size_t)(count * n));
  rng_state = seed;
  const double pi = 3.14159265358979323846;
  for (int k = 0; k < count; ++k)
  {
    for (int i = 0; i < n; ++i)
      q[k * n + i] = uniform(-pi, pi);
    for (int i = 0; i < n; ++i)
      v[k * n + i] = uniform(-1.0, 1.0);
    for (int i = 0; i < n; ++i)
      tau[k * n + i] = uniform(-1.0, 1.0);
  }

  double acc = 0;
#define EVALUATE(k)                                  \
  do                                                 \
  {                                                  \
    for (int i = 0; i < n; ++i)                      \
    {                                                \
      d->qpos[qadr[i]] = q[(k) * n + i];             \
      d->qvel[vadr[i]] = v[(k) * n + i];             \
      d->qfrc_applied[vadr[i]] = tau[(k) * n + i];   \
    }                                                \
    mj_forward(m, d);                                \
  } while (0)

  for (int k = 0; k < count; ++k) // warm-up
  {
    EVALUATE(k);
    acc += d->qacc[0];
  }
  double *per_call = malloc(sizeof(double) * (size_t)reps);
  for (int r = 0; r < reps; ++r)
  {
    double start = now_ns();
    for (int k = 0; k < count; ++k)
    {
      EVALUATE(k);
      acc += d->qacc[0];
    }
    per_call[r] = (now_ns() - start) / count;
  }
  sink = acc;
  double checksum = 0;
  for (int k = 0; k < count; ++k)
  {
    EVALUATE(k);
    for (int i = 0; i < n; ++i)
      checksum += d->qacc[vadr[i]];
  }
  qsort(per_call, (size_t)reps, sizeof(double), compare);
  double median = reps % 2 ? per_call[reps / 2]
                           : 0.5 * (per_call[reps / 2 - 1] + per_call[reps / 2]);
  printf("{\"impl\":\"mujoco\",\"build\":\"libmujoco from the mujoco wheel\",\"model\":\"%s\","
         "\"fn\":\"mj_forward\",\"batch\":%d,\"reps\":%d,\"median_ns\":%.2f,\"min_ns\":%.2f,"
         "\"max_ns\":%.2f,\"checksum\":%.17g}\n",
         name, count, reps, median, per_call[0], per_call[reps - 1], checksum);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
