/* ssx_hil_peer: the people and machines outside a hardware-in-the-loop run, as a ROS 2 node on DDS:
 * a motion-capture system played back from a file, and an operator at a joystick.
 *
 *   ssx_hil_peer FILE.csv [--lead S] [--wall-stamps] [--pillar X Y R] [--teleop OP VX VY START_S SECONDS]
 *                [--joy OP AXIS0 START_S SECONDS] [--watch ROBOT] [--image ROBOT W H] [--quiet]
 *
 * Motion capture. FILE.csv: a header `t,robot,x,y,z,qw,qx,qy,qz`, then one pose per line (t in
 * simulated seconds, rising per robot). Following ssx's /clock, each pose goes out on /<robot>/pose
 * (PoseStamped, stamped t) once the clock reaches t - S (--lead, default 0: as a live system, which
 * cannot send a pose before it measured it; a positive lead is a replay sending ahead). It reads what
 * ssx says of each robot in the file: /<robot>/odom (the ghost's pose as simulated, compared with the
 * file's poses interpolated at its stamp) and /<robot>/range (what the ghost's virtual range sensor
 * sees; with --pillar, a vertical cylinder at X Y of radius R that must be among the detections
 * whenever it is within 2.5 m, at its nearest point).
 *
 * Operator. With --teleop, from START_S of simulated time on, for SECONDS, it sends operator OP the
 * velocity VX VY (m/s; a Twist on /OP/cmd_vel, 20 per simulated second), then nothing (the dead-man
 * rule must stop the robots); it reads the force on /OP/force (WrenchStamped) and reports its largest
 * magnitude. --joy sends operator OP a joystick state (/OP/joy) stamped with each /clock it hears,
 * its axis 0 AXIS0 from START_S for SECONDS and 0 otherwise (lock-stepped, a joystick answers each
 * odometry round so). --watch ROBOT reports where that robot's odometry was at START_S, when the commands
 * ended, and at the end. --image ROBOT W H checks that robot's camera on /ROBOT/image: W x H rgb8
 * images, and reports how many came and how many show more than one colour.
 *
 * It follows the simulated time by /clock and by the robots' odometry stamps (reliable, where the
 * clock is best effort). It ends when the file is done and the clock is 0.5 s past its last pose (and the operator's part
 * 3 s past its commands), or when the clock stops for 3 s, and prints what it sent and found. Exit 0
 * when every robot was sent every pose, heard, and (with --pillar) the pillar was seen where it is;
 * 1 with a message otherwise (`FILE:LINE: error:` for a bad line). DDS configuration: CYCLONEDDS_URI
 * and ROS_DOMAIN_ID, as a ROS 2 node on this machine (docs/ros.md). */
#include "ros2_messages.h"

#include <dds/dds.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_ROBOTS 256
#define RANGE_M 2.5

typedef struct {
  double t, x, y, z, qw, qx, qy, qz;
  double sent_at;  /* the clock when it was sent */
} Sample;

typedef struct {
  char name[64];
  Sample* samples;
  size_t count, capacity, sent;
  dds_entity_t pose, odom, range;
  size_t odoms, ranges, pillar_seen, pillar_missed;
  double odom_error, pillar_error;
} Robot;

static Robot robots[MAX_ROBOTS];
static size_t robot_count = 0;

static double wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

static double seconds(builtin_interfaces_msg_dds__Time_ t) { return t.sec + t.nanosec * 1e-9; }

static builtin_interfaces_msg_dds__Time_ stamp(double t) {
  long long ns = llround(t * 1e9);
  builtin_interfaces_msg_dds__Time_ s = {(int32_t)(ns / 1000000000), (uint32_t)(ns % 1000000000)};
  return s;
}

static Robot* robotNamed(const char* name) {
  for (size_t i = 0; i < robot_count; ++i)
    if (strcmp(robots[i].name, name) == 0) return &robots[i];
  if (robot_count == MAX_ROBOTS) return NULL;
  Robot* r = &robots[robot_count++];
  memset(r, 0, sizeof *r);
  snprintf(r->name, sizeof r->name, "%s", name);
  return r;
}

/* reads the file; 0 on success, else prints FILE:LINE: error: and returns 1 */
static int readFile(const char* path) {
  FILE* f = fopen(path, "r");
  if (f == NULL) {
    fprintf(stderr, "%s: error: cannot open it\n", path);
    return 1;
  }
  char line[512];
  int number = 0;
  if (fgets(line, sizeof line, f) == NULL || strncmp(line, "t,robot,x,y,z,qw,qx,qy,qz", 25) != 0) {
    fprintf(stderr, "%s:1: error: the header must be t,robot,x,y,z,qw,qx,qy,qz\n", path);
    fclose(f);
    return 1;
  }
  number = 1;
  while (fgets(line, sizeof line, f) != NULL) {
    ++number;
    Sample s;
    char name[64];
    if (sscanf(line, "%lf,%63[^,],%lf,%lf,%lf,%lf,%lf,%lf,%lf", &s.t, name, &s.x, &s.y, &s.z, &s.qw, &s.qx, &s.qy,
               &s.qz) != 9 || !isfinite(s.t) || !isfinite(s.x) || !isfinite(s.y) || !isfinite(s.z)) {
      fprintf(stderr, "%s:%d: error: not t,robot,x,y,z,qw,qx,qy,qz with finite numbers\n", path, number);
      fclose(f);
      return 1;
    }
    Robot* r = robotNamed(name);
    if (r == NULL) {
      fprintf(stderr, "%s:%d: error: more than %d robots\n", path, number, MAX_ROBOTS);
      fclose(f);
      return 1;
    }
    if (r->count > 0 && !(s.t > r->samples[r->count - 1].t)) {
      fprintf(stderr, "%s:%d: error: t does not rise for robot '%s'\n", path, number, name);
      fclose(f);
      return 1;
    }
    if (r->count == r->capacity) {
      r->capacity = r->capacity ? 2 * r->capacity : 256;
      r->samples = realloc(r->samples, r->capacity * sizeof(Sample));
    }
    r->samples[r->count++] = s;
  }
  fclose(f);
  if (robot_count == 0) {
    fprintf(stderr, "%s: error: no poses in it\n", path);
    return 1;
  }
  return 0;
}

/* the file's position of robot r at time t, interpolated; 0 when t is outside its samples or the
 * later of the two was sent less than half the lead before t in simulated time (it may not have
 * arrived yet on a loaded machine) */
static double margin = 0.02;
static int positionAt(const Robot* r, double t, double out[3]) {
  if (r->count < 2 || t < r->samples[0].t || t > r->samples[r->count - 1].t) return 0;
  size_t lo = 0, hi = r->count - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (r->samples[mid].t <= t) lo = mid; else hi = mid;
  }
  const Sample* a = &r->samples[lo];
  const Sample* b = &r->samples[hi];
  if (hi >= r->sent || b->sent_at + margin > t) return 0;
  const double u = (t - a->t) / (b->t - a->t);
  out[0] = a->x + u * (b->x - a->x);
  out[1] = a->y + u * (b->y - a->y);
  out[2] = a->z + u * (b->z - a->z);
  return 1;
}

static dds_qos_t* qos(int reliable, int depth) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_MSECS(100));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, xcdr1);
  return q;
}

static dds_entity_t topic(dds_entity_t participant, const dds_topic_descriptor_t* type, const char* robot,
                          const char* what) {
  char name[128];
  snprintf(name, sizeof name, "rt/%s/%s", robot, what);
  return dds_create_topic(participant, type, name, NULL, NULL);
}

int main(int argc, char** argv) {
  const char* file = NULL;
  double lead = 0, pillar[3] = {0, 0, 0};
  int check_pillar = 0, quiet = 0, wall_stamps = 0;
  const char* teleop = NULL;
  const char* joy_op = NULL;
  double joy_axis = 0, joy_start = 0, joy_seconds = 0;
  const char* watch = NULL;
  const char* image_robot = NULL;
  unsigned image_size[2] = {0, 0};
  double teleop_v[2] = {0, 0}, teleop_start = 0, teleop_seconds = 0;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--lead") == 0 && i + 1 < argc) {
      lead = atof(argv[++i]);
    } else if (strcmp(argv[i], "--pillar") == 0 && i + 3 < argc) {
      for (int k = 0; k < 3; ++k) pillar[k] = atof(argv[++i]);
      check_pillar = 1;
    } else if (strcmp(argv[i], "--teleop") == 0 && i + 5 < argc) {
      teleop = argv[++i];
      teleop_v[0] = atof(argv[++i]);
      teleop_v[1] = atof(argv[++i]);
      teleop_start = atof(argv[++i]);
      teleop_seconds = atof(argv[++i]);
    } else if (strcmp(argv[i], "--image") == 0 && i + 3 < argc) {
      image_robot = argv[++i];
      image_size[0] = (unsigned)atoi(argv[++i]);
      image_size[1] = (unsigned)atoi(argv[++i]);
    } else if (strcmp(argv[i], "--joy") == 0 && i + 4 < argc) {
      joy_op = argv[++i];
      joy_axis = atof(argv[++i]);
      joy_start = atof(argv[++i]);
      joy_seconds = atof(argv[++i]);
    } else if (strcmp(argv[i], "--watch") == 0 && i + 1 < argc) {
      watch = argv[++i];
    } else if (strcmp(argv[i], "--wall-stamps") == 0) {
      wall_stamps = 1;
    } else if (strcmp(argv[i], "--quiet") == 0) {
      quiet = 1;
    } else if (file == NULL && argv[i][0] != '-') {
      file = argv[i];
    } else {
      fprintf(stderr, "usage: ssx_hil_peer FILE.csv [--lead S] [--wall-stamps] [--pillar X Y R] [--teleop OP VX VY START_S SECONDS] [--joy OP AXIS0 START_S SECONDS] [--watch ROBOT] [--image ROBOT W H] [--quiet]\n");
      return 1;
    }
  }
  if (file == NULL) {
    fprintf(stderr, "usage: ssx_hil_peer FILE.csv [--lead S] [--wall-stamps] [--pillar X Y R] [--teleop OP VX VY START_S SECONDS] [--joy OP AXIS0 START_S SECONDS] [--watch ROBOT] [--image ROBOT W H] [--quiet]\n");
    return 1;
  }
  if (readFile(file) != 0) return 1;
  if (lead > 0) margin = lead / 2;

  const char* domain_env = getenv("ROS_DOMAIN_ID");
  const dds_domainid_t domain = domain_env != NULL ? (dds_domainid_t)atoi(domain_env) : 0;
  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "ssx_hil_peer: no DDS participant: %s\n", dds_strretcode(participant));
    return 1;
  }
  dds_qos_t* reliable = qos(1, 100);
  dds_qos_t* clockq = qos(0, 1);
  for (size_t i = 0; i < robot_count; ++i) {
    Robot* r = &robots[i];
    r->pose = dds_create_writer(participant, topic(participant, &geometry_msgs_msg_dds__PoseStamped__desc, r->name, "pose"),
                                reliable, NULL);
    r->odom = dds_create_reader(participant, topic(participant, &nav_msgs_msg_dds__Odometry__desc, r->name, "odom"),
                                reliable, NULL);
    r->range = dds_create_reader(participant, topic(participant, &geometry_msgs_msg_dds__PoseArray__desc, r->name, "range"),
                                 reliable, NULL);
  }
  dds_entity_t twist = 0, force = 0, watched = 0;
  if (teleop != NULL) {
    twist = dds_create_writer(participant, topic(participant, &geometry_msgs_msg_dds__Twist__desc, teleop, "cmd_vel"),
                              reliable, NULL);
    force = dds_create_reader(participant, topic(participant, &geometry_msgs_msg_dds__WrenchStamped__desc, teleop, "force"),
                              reliable, NULL);
  }
  dds_entity_t joy = 0;
  double joy_sent_at = -1;
  if (joy_op != NULL)
    joy = dds_create_writer(participant, topic(participant, &sensor_msgs_msg_dds__Joy__desc, joy_op, "joy"), reliable, NULL);
  dds_entity_t images = 0;
  size_t image_count = 0, image_bad = 0, image_varied = 0;
  if (image_robot != NULL)
    images = dds_create_reader(participant, topic(participant, &sensor_msgs_msg_dds__Image__desc, image_robot, "image"),
                               reliable, NULL);
  if (watch != NULL)
    watched = dds_create_reader(participant, topic(participant, &nav_msgs_msg_dds__Odometry__desc, watch, "odom"),
                                reliable, NULL);
  const dds_entity_t clock_reader = dds_create_reader(
      participant, dds_create_topic(participant, &rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", NULL, NULL), clockq, NULL);
  dds_delete_qos(reliable);
  dds_delete_qos(clockq);

  double now = -1, last_tick = wall();
  const double started = wall();
  double end = 0;
  for (size_t i = 0; i < robot_count; ++i) end = fmax(end, robots[i].samples[robots[i].count - 1].t);
  if (teleop != NULL) end = fmax(end, teleop_start + teleop_seconds + 3.0);
  double next_twist = teleop_start, max_force = 0, forces = 0;
  double watched_at[3][3] = {{NAN, NAN, NAN}, {NAN, NAN, NAN}, {NAN, NAN, NAN}};  /* at start, end of commands, last */
  void* samples[1] = {NULL};
  dds_sample_info_t info[1];
  for (;;) {
    while (dds_take(clock_reader, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const double t = seconds(((rosgraph_msgs_msg_dds__Clock_*)samples[0])->clock);
        if (t > now) last_tick = wall();
        now = fmax(now, t);
      }
      dds_return_loan(clock_reader, samples, 1);
    }
    for (size_t i = 0; i < robot_count; ++i) {
      Robot* r = &robots[i];
      /* the poses due: measured (stamp - lead) by now */
      for (; now >= 0 && r->sent < r->count && r->samples[r->sent].t - lead <= now; ++r->sent) {
        Sample* s = &r->samples[r->sent];
        s->sent_at = now;
        geometry_msgs_msg_dds__PoseStamped_ m;
        memset(&m, 0, sizeof m);
        if (wall_stamps) {
          struct timespec ts;
          clock_gettime(CLOCK_REALTIME, &ts);
          m.header.stamp = stamp((double)ts.tv_sec + ts.tv_nsec * 1e-9 + (s->t - now));
        } else {
          m.header.stamp = stamp(s->t);
        }
        m.header.frame_id = "world";
        m.pose.position.x = s->x;
        m.pose.position.y = s->y;
        m.pose.position.z = s->z;
        m.pose.orientation.w = s->qw;
        m.pose.orientation.x = s->qx;
        m.pose.orientation.y = s->qy;
        m.pose.orientation.z = s->qz;
        dds_write(r->pose, &m);
      }
      while (dds_take(r->odom, samples, info, 1, 1) > 0) {
        if (info[0].valid_data) {
          const nav_msgs_msg_dds__Odometry_* m = samples[0];
          double p[3];
          /* (compared where the file has poses on both sides of the stamp, sent ahead of it) */
          const double t = seconds(m->header.stamp);
          /* the odometry says the time too, reliably: /clock is best effort, and lock-stepped a
           * lost one would leave ssx waiting for poses that only a clock tick would send */
          if (t > now) {
            now = t;
            last_tick = wall();
          }
          if (lead > 0 && t + lead <= end && positionAt(r, t, p)) {
            const double dx = m->pose.pose.position.x - p[0], dy = m->pose.pose.position.y - p[1],
                         dz = m->pose.pose.position.z - p[2];
            r->odom_error = fmax(r->odom_error, sqrt(dx * dx + dy * dy + dz * dz));
            ++r->odoms;
          }
        }
        dds_return_loan(r->odom, samples, 1);
      }
      while (dds_take(r->range, samples, info, 1, 1) > 0) {
        if (info[0].valid_data) {
          const geometry_msgs_msg_dds__PoseArray_* m = samples[0];
          ++r->ranges;
          double p[3];
          if (check_pillar && lead > 0 && positionAt(r, seconds(m->header.stamp), p)) {
            /* the pillar's nearest point, relative to the robot (world frame) */
            const double dx = p[0] - pillar[0], dy = p[1] - pillar[1], d = hypot(dx, dy);
            const double ex = pillar[0] + dx / d * pillar[2] - p[0], ey = pillar[1] + dy / d * pillar[2] - p[1];
            if (hypot(ex, ey) <= RANGE_M - 0.01) {
              double best = 1e9;
              for (uint32_t k = 0; k < m->poses._length; ++k) {
                const geometry_msgs_msg_dds__Point_* q = &m->poses._buffer[k].position;
                best = fmin(best, sqrt((q->x - ex) * (q->x - ex) + (q->y - ey) * (q->y - ey) + q->z * q->z));
              }
              if (best < 0.01) {
                ++r->pillar_seen;
                r->pillar_error = fmax(r->pillar_error, best);
              } else {
                ++r->pillar_missed;
              }
            }
          }
        }
        dds_return_loan(r->range, samples, 1);
      }
    }
    if (teleop != NULL && now >= next_twist && now < teleop_start + teleop_seconds) {
      geometry_msgs_msg_dds__Twist_ m;
      memset(&m, 0, sizeof m);
      m.linear.x = teleop_v[0];
      m.linear.y = teleop_v[1];
      dds_write(twist, &m);
      next_twist += 0.05;
    }
    if (joy != 0 && now > joy_sent_at) {
      float axes[4] = {0, 0, 0, 0};
      if (now >= joy_start && now < joy_start + joy_seconds) axes[0] = (float)joy_axis;
      sensor_msgs_msg_dds__Joy_ m;
      memset(&m, 0, sizeof m);
      m.header.stamp = stamp(now);
      m.header.frame_id = "";
      m.axes._buffer = axes;
      m.axes._length = m.axes._maximum = 4;
      dds_write(joy, &m);
      joy_sent_at = now;
    }
    while (force != 0 && dds_take(force, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const geometry_msgs_msg_dds__Vector3_* f = &((geometry_msgs_msg_dds__WrenchStamped_*)samples[0])->wrench.force;
        max_force = fmax(max_force, sqrt(f->x * f->x + f->y * f->y + f->z * f->z));
        ++forces;
      }
      dds_return_loan(force, samples, 1);
    }
    while (images != 0 && dds_take(images, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const sensor_msgs_msg_dds__Image_* m = samples[0];
        ++image_count;
        if (m->width != image_size[0] || m->height != image_size[1] || strcmp(m->encoding, "rgb8") != 0 ||
            m->step != 3 * m->width || m->data._length != m->step * m->height) {
          ++image_bad;
        } else {
          for (uint32_t k = 3; k < m->data._length; ++k)
            if (m->data._buffer[k] != m->data._buffer[k % 3]) {
              ++image_varied;
              break;
            }
        }
      }
      dds_return_loan(images, samples, 1);
    }
    while (watched != 0 && dds_take(watched, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const nav_msgs_msg_dds__Odometry_* m = samples[0];
        const double t = seconds(m->header.stamp);
        const double at[3] = {m->pose.pose.position.x, m->pose.pose.position.y, m->pose.pose.position.z};
        const int slot = t <= teleop_start ? 0 : t <= teleop_start + teleop_seconds ? 1 : 2;
        memcpy(watched_at[slot], at, sizeof at);
      }
      dds_return_loan(watched, samples, 1);
    }
    if (now >= end + 0.5) break;
    if (wall() - last_tick > 3.0 && (now >= 0 || wall() - started > 30)) break;
    dds_sleepfor(DDS_MSECS(1));
  }

  int ok = 1;
  for (size_t i = 0; i < robot_count; ++i) {
    const Robot* r = &robots[i];
    if (!quiet || r->sent < r->count || r->odoms == 0 || r->pillar_missed > 0)
      printf("%s: %zu of %zu poses sent; %zu odometry messages within %.6f m of the file's poses; %zu range messages, "
             "the pillar seen in %zu (within %.6f m), missed in %zu\n",
             r->name, r->sent, r->count, r->odoms, r->odom_error, r->ranges, r->pillar_seen, r->pillar_error,
             r->pillar_missed);
    if (r->sent < r->count || (lead > 0 && r->odoms == 0) || r->pillar_missed > 0 ||
        (check_pillar && (r->ranges == 0 || r->pillar_seen == 0)))
      ok = 0;
    free(robots[i].samples);
  }
  if (teleop != NULL) {
    printf("%s: %.0f force messages, the largest %.3f N\n", teleop, forces, max_force);
    if (forces == 0) ok = 0;
  }
  if (image_robot != NULL) {
    printf("%s: %zu images, %zu not %ux%u rgb8, %zu with more than one colour\n", image_robot, image_count, image_bad,
           image_size[0], image_size[1], image_varied);
    if (image_count == 0 || image_bad > 0) ok = 0;
  }
  if (watch != NULL) {
    printf("%s: at %.2f s x %.3f y %.3f; when the commands ended x %.3f y %.3f; at the end x %.3f y %.3f\n", watch,
           teleop_start, watched_at[0][0], watched_at[0][1], watched_at[1][0], watched_at[1][1], watched_at[2][0],
           watched_at[2][1]);
    if (isnan(watched_at[2][0])) ok = 0;
  }
  dds_delete(participant);
  if (!ok) fprintf(stderr, "ssx_hil_peer: not every robot was sent every pose and heard\n");
  return ok ? 0 : 1;
}
