/* A ROS 2 controller that is not ssx: a plain Cyclone DDS program built from the same IDL (ROS 2's
 * types), talking to the ros2 extension over loopback as a ROS 2 node would (topics rt/..., the
 * DDS configuration from CYCLONEDDS_URI, as docs/ros.md tells a ROS 2 user).
 *
 * It checks what ssx publishes: each topic's DDS type name and reliability (odometry reliable, IMU
 * and clock best effort, as ROS 2's default, sensor-data and clock QoS), odometry stamped every
 * 0.02 s of simulated time, /clock whole 0.01 s apart, twice as many IMU messages as odometry, and
 * it flies the robots:
 *
 *   peer COUNT TIMEOUT_S                 set-points: each robot q<i> 1 m east, 0.5 m south of where it
 *                                        started, 1.5 m up; success once every robot held within
 *                                        0.1 m for 1 s of simulated time
 *   peer COUNT TIMEOUT_S --cmd-vel       velocity commands: 0.5 m/s forward (a Twist, the robot's
 *                                        frame) for 2 s of simulated time, then 0; success once every
 *                                        robot moved 0.7-1.3 m along x and its odometry reached 0.4 m/s
 *   peer COUNT TIMEOUT_S --drive V W     as a ROS user drives a wheeled robot: a Twist of V m/s forward
 *                                        and W rad/s about z for 2 s of simulated time (from 1 s, once
 *                                        the writer matched ssx's reader), then 0; success once every
 *                                        robot's odometry went 2 V along its path (within 15 %), turned by
 *                                        2 W (within 10 %, unwrapped) and then stood (below 1 cm/s 4 s
 *                                        after the start); no IMU is asked for. Also /tf and
 *                                        joint states: each robot's q<i>/base_link on /tf at every
 *                                        odometry stamp, equal to its odometry's pose (1e-9); the last
 *                                        robot (a TurtleBot3 Burger) also its wheels' and caster's
 *                                        frames, the wheels 0.16 m apart, and /q<last>/joint_states
 *                                        naming both wheels, turning at the speeds the Twist asks
 *                                        mid-drive ((V -+ W 0.08) / 0.033 rad/s, their mean within 10 %);
 *                                        /tf_static with its deck fixed at (-0.032, 0, 0.21) in its
 *                                        base_link, and its /q<last>/robot_description a URDF naming
 *                                        its wheels (both transient local: kept for this late reader)
 *   peer COUNT TIMEOUT_S --lockstep      answers each odometry message after 0-30 ms with a set-point
 *                                        stamped like it; no odometry of a round may arrive before
 *                                        every robot's answer to the round before was sent; answers
 *                                        until the run ends (no odometry for 2 s); success after 100
 *                                        rounds or more with every robot holding its set-point
 *   peer COUNT SECONDS --bench           answers every odometry message at once with a set-point stamped
 *                                        like it for SECONDS, then prints how many messages came per
 *                                        robot (tests/unit/plugins/ros2/bench.sh)
 *   peer 1 TIMEOUT_S --wheels W R        as a ROS user drives a robot's joints: a JointState on
 *                                        /q0/joint_command naming the Husky's four wheels, first with a
 *                                        joint it lacks (ssx must drop that one), then at W rad/s for
 *                                        2 s of simulated time (from 1 s, once matched), then 0;
 *                                        success once q0 went 2 W R m ahead (within 15 %) and stood,
 *                                        its joint states showing the wheels at W mid-drive (mean
 *                                        within 10 %)
 *   --vanish-after S                     (with any) ends the process abruptly S wall seconds after the
 *                                        first odometry came (once connected: discovery can be slow)
 *
 * Exit 0 on success, 1 with a message otherwise. */
#include "ros2_messages.h"

#include <dds/dds.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define MAX_ROBOTS 128
#define SLOTS 256 /* odometry and /tf poses kept per robot, by stamp (every 0.02 s) */

/* a pose at a stamp: x y z qx qy qz qw */
typedef struct {
  double t;
  double v[7];
} Stamped;
static Stamped odom_at[MAX_ROBOTS][SLOTS], tf_at[MAX_ROBOTS][SLOTS];
static long tf_matched[MAX_ROBOTS], tf_mismatched = 0;

/* a pose arrived on one topic: compared with the other's at the same stamp, if it came first */
static void pair(Stamped (*mine)[SLOTS], Stamped (*theirs)[SLOTS], int robot, double t, const double* v) {
  const int slot = (int)(llround(t / 0.02) % SLOTS);
  mine[robot][slot].t = t;
  memcpy(mine[robot][slot].v, v, sizeof mine[robot][slot].v);
  const Stamped* other = &theirs[robot][slot];
  if (fabs(other->t - t) > 1e-9) return;
  double worst = 0;
  for (int k = 0; k < 7; ++k) worst = fmax(worst, fabs(other->v[k] - v[k]));
  if (worst <= 1e-9) ++tf_matched[robot];
  else if (tf_mismatched++ == 0) fprintf(stderr, "peer: q%d: /tf at %.3f s differs from its odometry by %g\n", robot, t, worst);
}

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

static dds_qos_t* qos(int reliable, int depth) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_MSECS(100));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, xcdr1);
  return q;
}

static int failures = 0;
static void fail(const char* what) {
  fprintf(stderr, "peer: %s\n", what);
  ++failures;
}

/* the type name and reliability of what matched `reader` (returns the matched count) */
static int checkPublisher(dds_entity_t reader, const char* type, int reliable) {
  dds_instance_handle_t handles[4];
  const dds_return_t n = dds_get_matched_publications(reader, handles, 4);
  for (int i = 0; i < n && i < 4; ++i) {
    dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader, handles[i]);
    if (e == NULL) continue;
    char line[256];
    if (strcmp(e->type_name, type) != 0) {
      snprintf(line, sizeof line, "%s: type %s, expected %s", e->topic_name, e->type_name, type);
      fail(line);
    }
    dds_reliability_kind_t kind;
    dds_duration_t blocking;
    if (dds_qget_reliability(e->qos, &kind, &blocking) && (kind == DDS_RELIABILITY_RELIABLE) != reliable) {
      snprintf(line, sizeof line, "%s: %s, expected %s", e->topic_name, kind == DDS_RELIABILITY_RELIABLE ? "reliable" : "best effort",
               reliable ? "reliable" : "best effort");
      fail(line);
    }
    dds_builtintopic_free_endpoint(e);
  }
  return n;
}

static const char* kWheels[4] = {"front_left_wheel_link", "rear_left_wheel_link", "front_right_wheel_link",
                                 "rear_right_wheel_link"};

/* --wheels: q0's four wheel joints driven by JointState commands */
static int wheelsMode(dds_entity_t participant, double timeout, double w, double radius) {
  dds_qos_t* q = qos(1, 100);
  const dds_entity_t odom =
      dds_create_reader(participant, dds_create_topic(participant, &nav_msgs_msg_dds__Odometry__desc, "rt/q0/odom", NULL, NULL), q, NULL);
  const dds_entity_t states = dds_create_reader(
      participant, dds_create_topic(participant, &sensor_msgs_msg_dds__JointState__desc, "rt/q0/joint_states", NULL, NULL), q, NULL);
  const dds_entity_t command = dds_create_writer(
      participant, dds_create_topic(participant, &sensor_msgs_msg_dds__JointState__desc, "rt/q0/joint_command", NULL, NULL), q, NULL);
  dds_delete_qos(q);
  double go = -1, x0 = 0, latest = -1, wheel_sum = 0;
  long wheel_samples = 0;
  int bad_sent = 0;
  void* samples[1] = {NULL};
  dds_sample_info_t info[1];
  const double started = wall();
  for (;;) {
    if (wall() - started > timeout) {
      fail("timed out");
      return 1;
    }
    int busy = 0;
    while (dds_take(odom, samples, info, 1, 1) > 0) {
      busy = 1;
      if (info[0].valid_data) {
        const nav_msgs_msg_dds__Odometry_* m = samples[0];
        const double t = seconds(m->header.stamp), x = m->pose.pose.position.x;
        latest = t;
        dds_publication_matched_status_t matched;
        if (go < 0 && t >= 1.0 && dds_get_publication_matched_status(command, &matched) == 0 && matched.current_count > 0)
          go = t, x0 = x;
        if (go >= 0 && t >= go + 4.0) {
          const double moved = x - x0, speed = hypot(m->twist.twist.linear.x, m->twist.twist.linear.y);
          const double mean = wheel_sum / (wheel_samples > 0 ? wheel_samples : 1);
          printf("peer: q0 went %.4f m (%.4f asked), %.4f m/s 4 s after the start; wheels at %.3f rad/s mid-drive (%.3f asked)\n",
                 moved, 2 * w * radius, speed, mean, w);
          if (fabs(moved - 2 * w * radius) > 0.15 * 2 * w * radius || speed > 0.01) fail("q0 did not drive as its wheels were told");
          if (wheel_samples < 30 || fabs(mean - w) > 0.1 * w) fail("the joint states do not show the wheels at the speed commanded");
          dds_return_loan(odom, samples, 1);
          return failures == 0 ? 0 : 1;
        }
      }
      dds_return_loan(odom, samples, 1);
    }
    while (dds_take(states, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const sensor_msgs_msg_dds__JointState_* m = samples[0];
        const double t = seconds(m->header.stamp);
        if (go >= 0 && t >= go + 0.5 && t <= go + 1.5) {
          /* each of the four wheels, found by name */
          for (uint32_t k = 0; k < m->name._length && k < m->velocity._length; ++k)
            for (int n = 0; n < 4; ++n)
              if (strcmp(m->name._buffer[k], kWheels[n]) == 0) wheel_sum += m->velocity._buffer[k], ++wheel_samples;
        }
      }
      dds_return_loan(states, samples, 1);
    }
    dds_publication_matched_status_t heard;
    if (busy && latest >= 0 && dds_get_publication_matched_status(command, &heard) == 0 && heard.current_count > 0) {
      /* only once ssx's reader has matched: a command written before is lost, the bad one with it */
      sensor_msgs_msg_dds__JointState_ cmd;
      memset(&cmd, 0, sizeof cmd);
      char* names[4] = {(char*)kWheels[0], (char*)kWheels[1], (char*)kWheels[2], (char*)kWheels[3]};
      double velocity[4];
      const int moving = go >= 0 && latest >= go && latest < go + 2.0;
      for (int n = 0; n < 4; ++n) velocity[n] = moving ? w : 0.0;
      if (!bad_sent) {
        /* a joint the robot lacks: the whole command is dropped, with a warning */
        names[3] = "no_such_joint";
        bad_sent = 1;
      }
      cmd.name._length = cmd.name._maximum = 4;
      cmd.name._buffer = names;
      cmd.velocity._length = cmd.velocity._maximum = 4;
      cmd.velocity._buffer = velocity;
      dds_write(command, &cmd);
    } else if (!busy) {
      usleep(200);
    }
  }
}

int main(int argc, char** argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: peer COUNT TIMEOUT_S [--lockstep|--cmd-vel|--drive V W] [--vanish-after S]\n");
    return 2;
  }
  const int count = atoi(argv[1]);
  const double timeout = atof(argv[2]);
  int lockstep = 0, cmd_vel = 0, bench = 0, drive = 0, wheels = 0;
  double wheel_speed = 0, wheel_radius = 0;
  double vanish = -1, drive_v = 0.5, drive_w = 0; /* the Twist sent from 1 s to 3 s */
  for (int i = 3; i < argc; ++i) {
    if (strcmp(argv[i], "--lockstep") == 0) lockstep = 1;
    else if (strcmp(argv[i], "--cmd-vel") == 0) cmd_vel = 1;
    else if (strcmp(argv[i], "--drive") == 0 && i + 2 < argc) cmd_vel = drive = 1, drive_v = atof(argv[i + 1]), drive_w = atof(argv[i + 2]), i += 2;
    else if (strcmp(argv[i], "--bench") == 0) bench = lockstep = 1;
    else if (strcmp(argv[i], "--wheels") == 0 && i + 2 < argc) wheels = 1, wheel_speed = atof(argv[i + 1]), wheel_radius = atof(argv[i + 2]), i += 2;
    else if (strcmp(argv[i], "--vanish-after") == 0 && i + 1 < argc) vanish = atof(argv[++i]);
  }
  if (count < 1 || count > MAX_ROBOTS) return 2;
  const char* domain_env = getenv("ROS_DOMAIN_ID");
  const dds_domainid_t domain = domain_env ? (dds_domainid_t)atoi(domain_env) : 0;
  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "peer: no DDS participant: %s\n", dds_strretcode(participant));
    return 1;
  }
  if (wheels) {
    const int status = wheelsMode(participant, timeout, wheel_speed, wheel_radius);
    dds_delete(participant);
    return status;
  }
  /* ROS 2's profiles; the odometry readers keep 100 (not 10), so that a peer slowed down by a loaded
     machine loses none and the stamps' spacing checks the writer's rate, not this reader's pace */
  dds_qos_t *reliable = qos(1, 10), *deep = qos(1, 100), *sensor = qos(0, 5), *clockq = qos(0, 1);
  dds_entity_t odom[MAX_ROBOTS], setpoint[MAX_ROBOTS], twist[MAX_ROBOTS];
  char name[128];
  for (int i = 0; i < count; ++i) {
    snprintf(name, sizeof name, "rt/q%d/odom", i);
    odom[i] = dds_create_reader(participant, dds_create_topic(participant, &nav_msgs_msg_dds__Odometry__desc, name, NULL, NULL), deep, NULL);
    snprintf(name, sizeof name, "rt/q%d/setpoint", i);
    setpoint[i] = dds_create_writer(participant, dds_create_topic(participant, &geometry_msgs_msg_dds__PoseStamped__desc, name, NULL, NULL), reliable, NULL);
    snprintf(name, sizeof name, "rt/q%d/cmd_vel", i);
    twist[i] = dds_create_writer(participant, dds_create_topic(participant, &geometry_msgs_msg_dds__Twist__desc, name, NULL, NULL), reliable, NULL);
  }
  const dds_entity_t imu_topic = dds_create_topic(participant, &sensor_msgs_msg_dds__Imu__desc, "rt/q0/imu", NULL, NULL);
  const dds_entity_t imu = dds_create_reader(participant, imu_topic, sensor, NULL);
  const dds_entity_t imu_reliable = dds_create_reader(participant, imu_topic, reliable, NULL);  /* must not match */
  const dds_entity_t clock_reader =
      dds_create_reader(participant, dds_create_topic(participant, &rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", NULL, NULL), clockq, NULL);
  /* /tf as tf2's listeners read it (reliable, 100 deep); the last robot's joint states */
  const dds_entity_t tf_reader =
      dds_create_reader(participant, dds_create_topic(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", NULL, NULL), deep, NULL);
  snprintf(name, sizeof name, "rt/q%d/joint_states", count - 1);
  const dds_entity_t joints_reader =
      dds_create_reader(participant, dds_create_topic(participant, &sensor_msgs_msg_dds__JointState__desc, name, NULL, NULL), deep, NULL);
  /* what is published once and kept (transient local), read as tf2's static listener reads it */
  dds_qos_t* latched = qos(1, 1);
  dds_qset_durability(latched, DDS_DURABILITY_TRANSIENT_LOCAL);
  const dds_entity_t static_reader = dds_create_reader(
      participant, dds_create_topic(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", NULL, NULL), latched, NULL);
  snprintf(name, sizeof name, "rt/q%d/robot_description", count - 1);
  const dds_entity_t description_reader =
      dds_create_reader(participant, dds_create_topic(participant, &std_msgs_msg_dds__String__desc, name, NULL, NULL), latched, NULL);
  dds_delete_qos(latched);
  int deck_seen = 0, description_seen = 0;
  long tf_messages = 0, wheel_frames = 0, joint_messages = 0, wheels_checked = 0;
  double left_sum = 0, right_sum = 0;
  int outside_pi = 0;
  for (int i = 0; i < count; ++i) {
    tf_matched[i] = 0;
    for (int k = 0; k < SLOTS; ++k) odom_at[i][k].t = tf_at[i][k].t = -1;
  }
  dds_delete_qos(reliable);
  dds_delete_qos(deep);
  dds_delete_qos(sensor);
  dds_delete_qos(clockq);

  double start_x[MAX_ROBOTS], start_y[MAX_ROBOTS], start_z[MAX_ROBOTS], latest_t[MAX_ROBOTS], held_since[MAX_ROBOTS];
  double fastest[MAX_ROBOTS], x_at_go[MAX_ROBOTS], answered[MAX_ROBOTS];
  double go[MAX_ROBOTS], path[MAX_ROBOTS], turned[MAX_ROBOTS], last_x[MAX_ROBOTS], last_y[MAX_ROBOTS], last_yaw[MAX_ROBOTS];
  int have_start[MAX_ROBOTS], done[MAX_ROBOTS];
  double pending_due[MAX_ROBOTS], pending_stamp[MAX_ROBOTS];
  for (int i = 0; i < count; ++i) {
    have_start[i] = done[i] = 0;
    latest_t[i] = held_since[i] = -1;
    fastest[i] = 0;
    x_at_go[i] = NAN;
    answered[i] = -1;
    pending_due[i] = -1;
    path[i] = turned[i] = 0;
    go[i] = NAN;
  }
  double last_clock = -1, imu_seen = 0, last_odom_wall = wall();
  long odom_messages = 0, clock_messages = 0, rounds = 0, violations = 0, per_robot[MAX_ROBOTS] = {0};
  int types_checked = 0;
  unsigned seed = 12345;
  const double started = wall();
  double connected = -1; /* when the first odometry came */
  void* samples[1] = {NULL};
  dds_sample_info_t info[1];
  for (;;) {
    const double now = wall();
    if (vanish > 0 && connected > 0 && now - connected > vanish) _exit(0); /* as a crashed controller: no goodbye */
    if (now - started > timeout) {
      if (!bench) fail("timed out");
      break;
    }
    int busy = 0;
    /* odometry */
    for (int i = 0; i < count; ++i) {
      while (dds_take(odom[i], samples, info, 1, 1) > 0) {
        busy = 1;
        if (info[0].valid_data) {
          const nav_msgs_msg_dds__Odometry_* m = samples[0];
          const double t = seconds(m->header.stamp);
          /* (the first comes after the first step, the next at 0.02 s: every 0.02 s from then on) */
          if (latest_t[i] >= 0.02 - 1e-9 && fabs(t - latest_t[i] - 0.02) > 1e-6 && !lockstep) {
            char line[160];
            snprintf(line, sizeof line, "q%d: odometry at %.6f s after %.6f s (every 0.02 s expected)", i, t, latest_t[i]);
            if (failures < 5) fail(line);
          }
          if (lockstep && i == 0 && latest_t[0] >= 0) {
            /* a new round: every robot must have answered the one before */
            for (int k = 0; k < count; ++k)
              if (answered[k] < latest_t[0] - 1e-9) ++violations;
            ++rounds;
          }
          latest_t[i] = t;
          ++odom_messages;
          if (connected < 0) connected = wall();
          ++per_robot[i];
          last_odom_wall = wall();
          const double x = m->pose.pose.position.x, y = m->pose.pose.position.y, z = m->pose.pose.position.z;
          if (!have_start[i]) start_x[i] = x, start_y[i] = y, start_z[i] = z, have_start[i] = 1;
          if (drive) {
            const double v[7] = {x, y, z, m->pose.pose.orientation.x, m->pose.pose.orientation.y, m->pose.pose.orientation.z,
                                 m->pose.pose.orientation.w};
            pair(odom_at, tf_at, i, t, v);
          }
          if (drive) {
            const double qw = m->pose.pose.orientation.w, qx = m->pose.pose.orientation.x, qy = m->pose.pose.orientation.y,
                         qz = m->pose.pose.orientation.z;
            const double yaw = atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz));
            dds_publication_matched_status_t matched;
            if (isnan(go[i]) && t >= 1.0 && dds_get_publication_matched_status(twist[i], &matched) == 0 && matched.current_count > 0)
              go[i] = t;
            else if (!isnan(go[i]) && !done[i]) {
              path[i] += hypot(x - last_x[i], y - last_y[i]);
              turned[i] += remainder(yaw - last_yaw[i], 2 * M_PI);
            }
            last_x[i] = x, last_y[i] = y, last_yaw[i] = yaw;
            if (t >= go[i] + 4.0 && !done[i]) {
              const double speed = hypot(m->twist.twist.linear.x, m->twist.twist.linear.y);
              char line[200];
              snprintf(line, sizeof line, "q%d: path %.4f m (%.4f asked), turned %.4f rad (%.4f asked), %.4f m/s 4 s after the start", i,
                       path[i], 2 * drive_v, turned[i], 2 * drive_w, speed);
              if (fabs(path[i] - 2 * drive_v) > 0.15 * fabs(2 * drive_v) + 1e-3 ||
                  fabs(turned[i] - 2 * drive_w) > 0.1 * fabs(2 * drive_w) + 1e-2 || speed > 0.01)
                fail(line);
              else
                printf("peer: %s\n", line);
              done[i] = 1;
            }
          } else if (cmd_vel) {
            if (t >= 1.0 && isnan(x_at_go[i])) x_at_go[i] = x;
            if (m->twist.twist.linear.x > fastest[i]) fastest[i] = m->twist.twist.linear.x;
            if (t >= 5.0 && !done[i]) {
              const double moved = x - x_at_go[i];
              if (moved >= 0.7 && moved <= 1.3 && fastest[i] >= 0.4) done[i] = 1;
              else {
                char line[160];
                snprintf(line, sizeof line, "q%d moved %.3f m, fastest %.3f m/s", i, moved, fastest[i]);
                fail(line);
                done[i] = 1;
              }
            }
          } else {
            const double dx = x - (start_x[i] + 1), dy = y - (start_y[i] - 0.5), dz = z - (start_z[i] + 1.5);
            if (sqrt(dx * dx + dy * dy + dz * dz) < 0.1) {
              if (held_since[i] < 0) held_since[i] = t;
              if (t - held_since[i] >= 1.0) done[i] = 1;
            } else {
              held_since[i] = -1;
            }
            if (lockstep) {
              pending_due[i] = wall() + (bench ? 0 : (rand_r(&seed) % 31) * 1e-3);
              pending_stamp[i] = t;
            }
          }
        }
        dds_return_loan(odom[i], samples, 1);
      }
    }
    /* the answers */
    for (int i = 0; i < count; ++i) {
      if (!have_start[i]) continue;
      if (cmd_vel) {
        if (latest_t[i] < 0) continue;
        geometry_msgs_msg_dds__Twist_ tw;
        memset(&tw, 0, sizeof tw);
        /* --drive: from its first odometry at or after 1 s once this writer matched ssx's reader */
        const double from = drive ? go[i] : 1.0;
        const int moving = latest_t[i] >= from && latest_t[i] < from + 2.0;
        tw.linear.x = moving ? drive_v : 0.0;
        tw.angular.z = moving ? drive_w : 0.0;
        dds_write(twist[i], &tw);
        continue;
      }
      if (lockstep && (pending_due[i] < 0 || wall() < pending_due[i])) continue;
      geometry_msgs_msg_dds__PoseStamped_ sp;
      memset(&sp, 0, sizeof sp);
      sp.header.stamp = stamp(lockstep ? pending_stamp[i] : latest_t[i]);
      sp.header.frame_id = "world";
      sp.pose.position.x = start_x[i] + 1;
      sp.pose.position.y = start_y[i] - 0.5;
      sp.pose.position.z = start_z[i] + 1.5;
      sp.pose.orientation.w = 1;
      if (lockstep) {
        dds_write(setpoint[i], &sp);
        answered[i] = pending_stamp[i];
        pending_due[i] = -1;
      } else if (busy) {
        dds_write(setpoint[i], &sp);
      }
    }
    /* the clock and the IMU */
    while (dds_take(clock_reader, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const double t = seconds(((const rosgraph_msgs_msg_dds__Clock_*)samples[0])->clock);
        /* (the first comes after the first step; then every 0.01 s of simulated time, some may be lost: best effort) */
        const double steps = (t - last_clock) / 0.01;
        if (last_clock >= 0.01 && (fabs(steps - llround(steps)) > 1e-6 || steps < 0.5) && failures < 5) {
          char line[160];
          snprintf(line, sizeof line, "/clock at %.6f s after %.6f s (whole 0.01 s apart expected)", t, last_clock);
          fail(line);
        }
        last_clock = t;
        ++clock_messages;
      }
      dds_return_loan(clock_reader, samples, 1);
    }
    /* /tf: every robot's base_link, the last one's parts */
    while (drive && dds_take(tf_reader, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const tf2_msgs_msg_dds__TFMessage_* m = samples[0];
        ++tf_messages;
        double left[3] = {NAN, NAN, NAN}, right[3] = {NAN, NAN, NAN};
        for (uint32_t k = 0; k < m->transforms._length; ++k) {
          const geometry_msgs_msg_dds__TransformStamped_* ts = &m->transforms._buffer[k];
          const geometry_msgs_msg_dds__Transform_* tr = &ts->transform;
          int robot = -1;
          char part[64] = "";
          if (strcmp(ts->header.frame_id, "world") != 0 && failures < 5) fail("a /tf transform not in the world frame");
          if (sscanf(ts->child_frame_id, "q%d/%63s", &robot, part) != 2 || robot < 0 || robot >= count) continue;
          const double v[7] = {tr->translation.x, tr->translation.y, tr->translation.z, tr->rotation.x, tr->rotation.y,
                               tr->rotation.z, tr->rotation.w};
          if (strcmp(part, "base_link") == 0) pair(tf_at, odom_at, robot, seconds(ts->header.stamp), v);
          if (robot == count - 1 && strcmp(part, "left_wheel") == 0) memcpy(left, v, sizeof left);
          if (robot == count - 1 && strcmp(part, "right_wheel") == 0) memcpy(right, v, sizeof right);
        }
        if (!isnan(left[0]) && !isnan(right[0])) {
          const double apart = sqrt(pow(left[0] - right[0], 2) + pow(left[1] - right[1], 2) + pow(left[2] - right[2], 2));
          if (fabs(apart - 0.16) > 0.005 && failures < 5) {
            char line[120];
            snprintf(line, sizeof line, "q%d's wheels on /tf are %.4f m apart, not 0.16", count - 1, apart);
            fail(line);
          }
          ++wheel_frames;
        }
      }
      dds_return_loan(tf_reader, samples, 1);
    }
    /* once: the fixed frames and the description */
    while (drive && dds_take(static_reader, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const tf2_msgs_msg_dds__TFMessage_* m = samples[0];
        char deck[64], base[64];
        snprintf(deck, sizeof deck, "q%d/deck", count - 1);
        snprintf(base, sizeof base, "q%d/base_link", count - 1);
        for (uint32_t k = 0; k < m->transforms._length; ++k) {
          const geometry_msgs_msg_dds__TransformStamped_* ts = &m->transforms._buffer[k];
          if (strcmp(ts->child_frame_id, deck) != 0) continue;
          const geometry_msgs_msg_dds__Vector3_* p = &ts->transform.translation;
          if (strcmp(ts->header.frame_id, base) != 0 || fabs(p->x + 0.032) > 1e-9 || fabs(p->y) > 1e-9 || fabs(p->z - 0.21) > 1e-9)
            fail("/tf_static: the Burger's deck is not at (-0.032, 0, 0.21) in its base_link");
          deck_seen = 1;
        }
      }
      dds_return_loan(static_reader, samples, 1);
    }
    while (drive && dds_take(description_reader, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const char* text = ((const std_msgs_msg_dds__String_*)samples[0])->data;
        char robot[64];
        snprintf(robot, sizeof robot, "<robot name=\"q%d\">", count - 1);
        if (strstr(text, robot) == NULL || strstr(text, "<link name=\"left_wheel\">") == NULL ||
            strstr(text, "type=\"continuous\"") == NULL)
          fail("the Burger's robot_description is not a URDF of it with its wheels");
        description_seen = 1;
      }
      dds_return_loan(description_reader, samples, 1);
    }
    /* the last robot's wheels mid-drive, as the Twist asks */
    while (drive && dds_take(joints_reader, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) {
        const sensor_msgs_msg_dds__JointState_* m = samples[0];
        const double t = seconds(m->header.stamp);
        ++joint_messages;
        if (m->name._length != 2 || m->velocity._length != 2 || m->position._length != 2 ||
            strcmp(m->name._buffer[0], "left_wheel") != 0 || strcmp(m->name._buffer[1], "right_wheel") != 0) {
          if (failures < 5) fail("joint states: not left_wheel and right_wheel with a position and a velocity each");
        } else if (!isnan(go[count - 1]) && t >= go[count - 1] + 0.5 && t <= go[count - 1] + 1.5) {
          /* (each sample is the motor's speed at that step, which its torque limit and the caster's
             drag make ripple: their mean is compared at the end) */
          left_sum += m->velocity._buffer[0];
          right_sum += m->velocity._buffer[1];
          if (fabs(m->position._buffer[0]) > M_PI + 1e-9 || fabs(m->position._buffer[1]) > M_PI + 1e-9) outside_pi = 1;
          ++wheels_checked;
        }
      }
      dds_return_loan(joints_reader, samples, 1);
    }
    while (dds_take(imu, samples, info, 1, 1) > 0) {
      if (info[0].valid_data) ++imu_seen;
      dds_return_loan(imu, samples, 1);
    }
    if (!types_checked && odom_messages > 0 && clock_messages > 0 && (imu_seen > 0 || drive)) {
      checkPublisher(odom[0], "nav_msgs::msg::dds_::Odometry_", 1);
      if (!drive) checkPublisher(imu, "sensor_msgs::msg::dds_::Imu_", 0);
      checkPublisher(clock_reader, "rosgraph_msgs::msg::dds_::Clock_", 0);
      dds_subscription_matched_status_t st;
      dds_get_subscription_matched_status(imu_reliable, &st);
      if (st.current_count != 0) fail("a reliable reader matched the IMU's writer (sensor data is best effort)");
      types_checked = 1;
    }
    int all = 1;
    for (int i = 0; i < count; ++i) all &= done[i];
    /* in lock-step the run waits for every answer: answer until it ends (no odometry for 2 s) */
    if (all && (!lockstep || (rounds >= 100 && wall() - last_odom_wall > 2.0))) break;
    if (!busy) usleep(200);
  }
  if (bench) {
    long fewest = per_robot[0];
    for (int i = 1; i < count; ++i)
      if (per_robot[i] < fewest) fewest = per_robot[i];
    printf("peer: %d robots, at least %ld odometry messages each (%ld in all), %ld clock, %.0f IMU of q0\n", count,
           fewest, odom_messages, clock_messages, imu_seen);
    dds_delete(participant);
    return 0;
  }
  if (!types_checked) fail(drive ? "never saw odometry and clock together" : "never saw odometry, clock and IMU together");
  /* the IMU at 100 Hz against the odometry's 50 (best effort: a few may be lost) */
  if (!drive && per_robot[0] > 100 && (imu_seen < 1.8 * per_robot[0] || imu_seen > 2.2 * per_robot[0])) {
    char line[160];
    snprintf(line, sizeof line, "q0: %.0f IMU messages against %ld odometry (twice as many expected)", imu_seen, per_robot[0]);
    fail(line);
  }
  if (lockstep && violations > 0) fail("lock-step violated: odometry of a round came before every answer to the last");
  if (drive) {
    checkPublisher(tf_reader, "tf2_msgs::msg::dds_::TFMessage_", 1);
    checkPublisher(joints_reader, "sensor_msgs::msg::dds_::JointState_", 1);
    for (int i = 0; i < count; ++i) {
      if (tf_matched[i] < 100) {
        char line[120];
        snprintf(line, sizeof line, "q%d: /tf matched its odometry at only %ld stamps", i, tf_matched[i]);
        fail(line);
      }
    }
    if (tf_mismatched > 0) fail("/tf differed from the odometry");
    if (wheel_frames < 100 || wheels_checked < 30) fail("too few wheel frames on /tf or joint states mid-drive");
    const double want_left = (drive_v - drive_w * 0.08) / 0.033, want_right = (drive_v + drive_w * 0.08) / 0.033;
    const double left = left_sum / (wheels_checked > 0 ? wheels_checked : 1), right = right_sum / (wheels_checked > 0 ? wheels_checked : 1);
    char line[200];
    snprintf(line, sizeof line, "joint states mid-drive: wheels at %.3f and %.3f rad/s on average, %.3f and %.3f asked", left,
             right, want_left, want_right);
    if (fabs(left - want_left) > 0.1 * fabs(want_left) + 0.02 || fabs(right - want_right) > 0.1 * fabs(want_right) + 0.02)
      fail(line);
    else
      printf("peer: %s\n", line);
    if (outside_pi) fail("a joint state's position outside (-pi, pi]");
    if (!deck_seen) fail("no /tf_static with the Burger's deck");
    if (!description_seen) fail("no robot_description of the Burger");
    checkPublisher(static_reader, "tf2_msgs::msg::dds_::TFMessage_", 1);
    checkPublisher(description_reader, "std_msgs::msg::dds_::String_", 1);
    printf("peer: %ld /tf messages (q0's base_link equal to its odometry at %ld stamps), %ld with both wheels, %ld joint "
           "states (%ld mid-drive)\n", tf_messages, tf_matched[0], wheel_frames, joint_messages, wheels_checked);
  }
  printf("peer: %ld odometry, %ld clock messages, %.0f IMU; %ld rounds, %ld violations; %d failure(s)\n", odom_messages,
         clock_messages, imu_seen, rounds, violations, failures);
  dds_delete(participant);
  return failures == 0 ? 0 : 1;
}
