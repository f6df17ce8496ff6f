/* A ROS 2 subscriber that is not ssx (a Cyclone DDS program with ROS 2's types from the same IDL):
 * against tests/unit/plugins/ros2/ros2_sensors.xml it reads /q0/scan (sensor_msgs/LaserScan: the
 * e-puck's eight rays on a grid of one degree, NaN between them, the two rays facing the wall 6.6 cm
 * from the robot's axis at 0.066 / cos(17 deg) m, the others +inf), and /q1/camera_info beside
 * /q1/image (a pinhole: fx = fy = 32 / tan(30 deg), centre 32, 24, for 64 x 48 and 60 degrees),
 * /q0/range_bearing (ssx_msgs/RangeBearing: q2's 4-byte payload from 0.3 m to the left) and
 * /q0/ground (ssx_msgs/Ground: one point, its grey and colour), and /tf_static: every sensor's frame
 * resolves (q0/scan 3 cm above q0's base where its rays start, q1/camera at its mount, its optical
 * frame z forward, x right, y down, q1/imu at its body), and each message names its sensor's frame.
 *   sensors_peer TIMEOUT_S            exit 0 when all held */
#include "ros2_messages.h"

#include <dds/dds.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;
static void check(int ok, const char* what) {
  printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++failures;
}

static dds_entity_t subscribe(dds_entity_t p, const dds_topic_descriptor_t* type, const char* name, int reliable) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
  if (reliable == 2) dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL); /* (tf2's /tf_static) */
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 5);
  const dds_entity_t r = dds_create_reader(p, dds_create_topic(p, type, name, NULL, NULL), q, NULL);
  dds_delete_qos(q);
  return r;
}

/* the next sample of `reader` into `out` (caller frees its contents), 0 after the timeout */
static int next(dds_entity_t reader, void* out, double timeout) {
  for (double waited = 0; waited < timeout; waited += 0.005) {
    void* buf[1] = {out};
    dds_sample_info_t info;
    if (dds_take(reader, buf, &info, 1, 1) == 1 && info.valid_data) return 1;
    dds_sleepfor(DDS_MSECS(5));
  }
  return 0;
}

/* the transform in `m` to `child` from its parent `parent`, NULL when there is none */
static const geometry_msgs_msg_dds__TransformStamped_* find(const tf2_msgs_msg_dds__TFMessage_* m, const char* parent,
                                                            const char* child) {
  for (uint32_t k = 0; k < m->transforms._length; ++k) {
    const geometry_msgs_msg_dds__TransformStamped_* t = &m->transforms._buffer[k];
    if (strcmp(t->child_frame_id, child) == 0 && strcmp(t->header.frame_id, parent) == 0) return t;
  }
  return NULL;
}

/* `v` turned by the transform's rotation */
static void turn(const geometry_msgs_msg_dds__TransformStamped_* t, const double v[3], double out[3]) {
  const double x = t->transform.rotation.x, y = t->transform.rotation.y, z = t->transform.rotation.z,
               w = t->transform.rotation.w;
  const double c[3] = {y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]}; /* q x v */
  const double cc[3] = {y * c[2] - z * c[1], z * c[0] - x * c[2], x * c[1] - y * c[0]};
  for (int i = 0; i < 3; ++i) out[i] = v[i] + 2 * w * c[i] + 2 * cc[i];
}

static int near3(const double a[3], double x, double y, double z) {
  return fabs(a[0] - x) < 1e-9 && fabs(a[1] - y) < 1e-9 && fabs(a[2] - z) < 1e-9;
}

static void checkStaticFrames(const tf2_msgs_msg_dds__TFMessage_* m) {
  printf("  /tf_static: %u frames\n", m->transforms._length);
  const geometry_msgs_msg_dds__TransformStamped_* scan = find(m, "q0/base_link", "q0/scan");
  check(scan && scan->transform.translation.x == 0 && scan->transform.translation.y == 0 &&
            fabs(scan->transform.translation.z - 0.03) < 1e-12 && scan->transform.rotation.w == 1,
        "q0/scan: 3 cm above q0/base_link (the rays' height), not turned");
  const geometry_msgs_msg_dds__TransformStamped_* camera = find(m, "q1/base_link", "q1/camera");
  check(camera && fabs(camera->transform.translation.x - 0.1) < 1e-12 && camera->transform.rotation.w == 1,
        "q1/camera: at its mount, 0.1 m ahead of q1/base_link");
  const geometry_msgs_msg_dds__TransformStamped_* optical = find(m, "q1/camera", "q1/camera_optical");
  if (optical == NULL) return check(0, "q1/camera_optical in q1/camera");
  const double ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0}, ez[3] = {0, 0, 1};
  double x[3], y[3], z[3];
  turn(optical, ex, x), turn(optical, ey, y), turn(optical, ez, z);
  printf("  optical axes in q1/camera: x %.3f %.3f %.3f, y %.3f %.3f %.3f, z %.3f %.3f %.3f\n", x[0], x[1], x[2], y[0],
         y[1], y[2], z[0], z[1], z[2]);
  check(near3(z, 1, 0, 0) && near3(x, 0, -1, 0) && near3(y, 0, 0, -1),
        "q1/camera_optical: z forward (the camera's x), x right, y down");
  const geometry_msgs_msg_dds__TransformStamped_* imu = find(m, "q1/base_link", "q1/imu");
  check(imu && imu->transform.translation.x == 0 && imu->transform.rotation.w == 1, "q1/imu: at q1's body");
}

int main(int argc, char** argv) {
  setvbuf(stdout, NULL, _IONBF, 0);
  const double timeout = argc > 1 ? atof(argv[1]) : 30;
  const char* domain_env = getenv("ROS_DOMAIN_ID");
  const dds_entity_t p = dds_create_participant(domain_env ? (dds_domainid_t)atoi(domain_env) : 0, NULL, NULL);
  if (p < 0) return fprintf(stderr, "sensors_peer: no DDS participant\n"), 1;
  const dds_entity_t scan = subscribe(p, &sensor_msgs_msg_dds__LaserScan__desc, "rt/q0/scan", 0);
  const dds_entity_t info = subscribe(p, &sensor_msgs_msg_dds__CameraInfo__desc, "rt/q1/camera_info", 1);
  const dds_entity_t image = subscribe(p, &sensor_msgs_msg_dds__Image__desc, "rt/q1/image", 1);
  const dds_entity_t rab = subscribe(p, &ssx_msgs_msg_dds__RangeBearing__desc, "rt/q0/range_bearing", 1);
  const dds_entity_t ground = subscribe(p, &ssx_msgs_msg_dds__Ground__desc, "rt/q0/ground", 0);
  const dds_entity_t tf_static = subscribe(p, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", 2);
  const dds_entity_t imu = subscribe(p, &sensor_msgs_msg_dds__Imu__desc, "rt/q1/imu", 0);

  /* (the first scans come before the robot settles on the ground: the 8th is looked at) */
  void* loan[1] = {NULL};
  int got = 0;
  for (double waited = 0; got < 8 && waited < timeout; waited += 0.005) {
    dds_sample_info_t si;
    if (loan[0] != NULL) dds_return_loan(scan, loan, 1), loan[0] = NULL;
    if (dds_take(scan, loan, &si, 1, 1) == 1) {
      if (si.valid_data) ++got;
    } else {
      loan[0] = NULL;
      dds_sleepfor(DDS_MSECS(5));
    }
  }
  check(got == 8, "/q0/scan arrives (best effort)");
  if (got == 8) {
    const sensor_msgs_msg_dds__LaserScan_ s = *(const sensor_msgs_msg_dds__LaserScan_*)loan[0];
    const double deg = M_PI / 180;
    printf("  scan: %u ranges from %.4f rad by %.6f rad, range %.3f to %.3f m, frame %s\n", s.ranges._length, s.angle_min,
           s.angle_increment, s.range_min, s.range_max, s.header.frame_id);
    check(s.ranges._length == 303 && fabs(s.angle_min + 151 * deg) < 1e-6 && fabs(s.angle_increment - deg) < 1e-6,
          "the e-puck's ring on a grid of one degree from -151 degrees (303 slots)");
    check(fabs(s.range_min - 0.036) < 1e-6 && fabs(s.range_max - 0.086) < 1e-6, "range from the ring (3.6 cm) to 8.6 cm");
    check(strcmp(s.header.frame_id, "q0/scan") == 0, "in the ring's frame, q0/scan");
    const int rays[8] = {-17, -46, -90, -151, 151, 90, 46, 17};
    int nan_between = 1;
    for (uint32_t k = 0; k < s.ranges._length; ++k) {
      int is_ray = 0;
      for (int r = 0; r < 8; ++r) is_ray |= (int)k == rays[r] + 151;
      if (!is_ray && !isnan(s.ranges._buffer[k])) nan_between = 0;
    }
    check(nan_between, "NaN between the rays");
    const double wall = 0.066 / cos(17 * deg);
    if (s.ranges._length != 303) return printf("wrong ray grid\n"), 1;
    const float a = s.ranges._buffer[151 - 17], b = s.ranges._buffer[151 + 17];
    printf("  rays at -17 and 17 degrees: %.5f, %.5f m (the wall: %.5f m)\n", a, b, wall);
    check(fabs(a - wall) < 0.05 * wall && fabs(b - wall) < 0.05 * wall, "the rays facing the wall see it (5 %)");
    int far = 1;
    for (int r = 0; r < 8; ++r)
      if (abs(rays[r]) != 17) far &= isinf(s.ranges._buffer[rays[r] + 151]) && s.ranges._buffer[rays[r] + 151] > 0;
    check(far, "the other six see nothing within range (+inf)");
    check(s.intensities._length == s.ranges._length && s.intensities._buffer[151 + 17] > 0, "intensities: the readings");
    dds_return_loan(scan, loan, 1);
  }

  sensor_msgs_msg_dds__CameraInfo_ c;
  sensor_msgs_msg_dds__Image_ im;
  memset(&c, 0, sizeof c);
  memset(&im, 0, sizeof im);
  const int got_info = next(info, &c, timeout), got_image = next(image, &im, timeout);
  check(got_info && got_image, "/q1/camera_info and /q1/image arrive");
  if (got_info && got_image) {
    const double f = 32 / tan(M_PI / 6);
    printf("  camera_info: %ux%u, K = [%.4f 0 %.1f; 0 %.4f %.1f; 0 0 1], %s, frame %s\n", c.width, c.height, c.k[0], c.k[2],
           c.k[4], c.k[5], c.distortion_model, c.header.frame_id);
    check(c.width == im.width && c.height == im.height && c.width == 64 && c.height == 48, "its size is the image's");
    check(fabs(c.k[0] - f) < 1e-9 && fabs(c.k[4] - f) < 1e-9 && c.k[2] == 32 && c.k[5] == 24 && c.k[8] == 1,
          "K: fx = fy = 32 / tan(30 deg), centre (32, 24)");
    check(c.p[0] == c.k[0] && c.p[2] == c.k[2] && c.p[10] == 1 && c.r[0] == 1 && c.r[4] == 1 && c.r[8] == 1 &&
              c.d._length == 5 && strcmp(c.distortion_model, "plumb_bob") == 0,
          "P as K, R the identity, no distortion (plumb_bob)");
    check(strcmp(c.header.frame_id, im.header.frame_id) == 0 && strcmp(c.header.frame_id, "q1/camera_optical") == 0,
          "in the image's frame, q1/camera_optical");
  }
  if (got_info) dds_sample_free(&c, &sensor_msgs_msg_dds__CameraInfo__desc, DDS_FREE_CONTENTS);

  /* ssx_msgs: what q0's range-and-bearing board received from q2, and its ground sensor */
  void* rl[1] = {NULL};
  dds_sample_info_t ri;
  int got_rab = 0;
  for (double waited = 0; !got_rab && waited < timeout; waited += 0.005) {
    if (dds_take(rab, rl, &ri, 1, 1) == 1) {
      const ssx_msgs_msg_dds__RangeBearing_* m = rl[0];
      if (ri.valid_data && m->messages._length == 1) {
        const ssx_msgs_msg_dds__RangeBearingMessage_* x = &m->messages._buffer[0];
        got_rab = 1;
        printf("  range_bearing: from %s, %.4f m, bearing %.4f rad, elevation %.4f rad, %u bytes\n", x->sender, x->range,
               x->bearing, x->elevation, x->data._length);
        check(strcmp(x->sender, "q2") == 0 && fabs(x->range - 0.3) < 0.03 && fabs(x->bearing - M_PI / 2) < 0.1 &&
                  x->data._length == 4,
              "q0 hears q2's 4 bytes from 0.3 m to its left");
      }
      dds_return_loan(rab, rl, 1);
    } else {
      dds_sleepfor(DDS_MSECS(5));
    }
  }
  check(got_rab, "/q0/range_bearing arrives");
  int got_ground = 0;
  for (double waited = 0; !got_ground && waited < timeout; waited += 0.005) {
    if (dds_take(ground, rl, &ri, 1, 1) == 1) {
      const ssx_msgs_msg_dds__Ground_* g = rl[0];
      if (ri.valid_data) {
        got_ground = 1;
        printf("  ground: %u reading(s), first %.3f, colour %.3f %.3f %.3f\n", g->readings._length,
               g->readings._length ? g->readings._buffer[0] : -1.0, g->colors._length > 2 ? g->colors._buffer[0] : -1.0,
               g->colors._length > 2 ? g->colors._buffer[1] : -1.0, g->colors._length > 2 ? g->colors._buffer[2] : -1.0);
        check(g->readings._length == 1 && g->colors._length == 3 && g->readings._buffer[0] >= 0 && g->readings._buffer[0] <= 1,
              "one ground point: a grey level 0..1 and its colour");
      }
      dds_return_loan(ground, rl, 1);
    } else {
      dds_sleepfor(DDS_MSECS(5));
    }
  }
  check(got_ground, "/q0/ground arrives");
  tf2_msgs_msg_dds__TFMessage_ statics;
  memset(&statics, 0, sizeof statics);
  const int got_statics = next(tf_static, &statics, timeout);
  check(got_statics, "/tf_static arrives (kept for later readers)");
  if (got_statics) checkStaticFrames(&statics), dds_sample_free(&statics, &tf2_msgs_msg_dds__TFMessage__desc, DDS_FREE_CONTENTS);
  sensor_msgs_msg_dds__Imu_ reading;
  memset(&reading, 0, sizeof reading);
  const int got_imu = next(imu, &reading, timeout);
  check(got_imu && strcmp(reading.header.frame_id, "q1/imu") == 0, "/q1/imu arrives, in the frame q1/imu");
  if (got_imu) dds_sample_free(&reading, &sensor_msgs_msg_dds__Imu__desc, DDS_FREE_CONTENTS);
  if (got_image) dds_sample_free(&im, &sensor_msgs_msg_dds__Image__desc, DDS_FREE_CONTENTS);
  dds_delete(p);
  printf("%d check(s) failed\n", failures);
  return failures == 0 ? 0 : 1;
}
