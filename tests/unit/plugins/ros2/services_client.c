/* A ROS 2 service client that is not ssx: a Cyclone DDS program calling the simulation_interfaces
 * services as rmw_cyclonedds_cpp puts them on DDS (rq/<name>Request, rr/<name>Reply, each sample
 * led by the client's id and the call's number), with the types built from the same IDL.
 *
 *   services_client TIMEOUT_S
 *
 * Against ssx running tests/unit/plugins/ros2/ros2_services.xml (q0 and q1, real time), it checks
 * every service's reply, and that pausing holds time, stepping takes exactly the steps asked,
 * an entity set while paused reads back as set, a reset goes back to time 0 and the same steps
 * after it give the same bits; it prints each call's round trip (median and p99) while the run
 * plays and while it is paused, then asks the run to quit. Exit 0 when all held. */
#include "ros2_messages.h"

#include <dds/dds.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { FEATURES, GET_STATE, SET_STATE, STEP, RESET, ENTITIES, GET_ENTITY, SET_ENTITY, SPAWN, DELETE, KINDS };
static const char* kNames[KINDS] = {"get_simulator_features", "get_simulation_state", "set_simulation_state",
                                    "step_simulation", "reset_simulation", "get_entities", "get_entity_state",
                                    "set_entity_state", "spawn_entity", "delete_entity"};
#define DESCS(T) &simulation_interfaces_srv_dds__##T##_Request__desc, &simulation_interfaces_srv_dds__##T##_Response__desc
static const dds_topic_descriptor_t* kTypes[KINDS][2] = {
    {DESCS(GetSimulatorFeatures)}, {DESCS(GetSimulationState)}, {DESCS(SetSimulationState)}, {DESCS(StepSimulation)},
    {DESCS(ResetSimulation)},      {DESCS(GetEntities)},        {DESCS(GetEntityState)},     {DESCS(SetEntityState)},
    {DESCS(SpawnEntity)},          {DESCS(DeleteEntity)}};

typedef struct {
  uint64_t guid;
  int64_t seq;
} Header;

static dds_entity_t writers[KINDS], readers[KINDS];
static uint64_t guid;
static int64_t sequence;
static double timeout;
static int failures;
static double trips[2][512];
static int trip_count[2];
static int timing_phase = -1; /* 0 playing, 1 paused: where round trips are kept */

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void check(int ok, const char* what) {
  printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++failures;
}

/* writes `request` (its header filled here) and returns the reply with the same header (caller
   frees with dds_sample_free), NULL after the timeout */
static void* call(int kind, void* request) {
  Header* h = (Header*)request;
  h->guid = guid;
  h->seq = ++sequence;
  const double t0 = now();
  if (dds_write(writers[kind], request) < 0) return NULL;
  void* reply = calloc(1, kTypes[kind][1]->m_size);
  while (now() - t0 < 10.0) {
    dds_sample_info_t info;
    void* buf[1] = {reply};
    if (dds_take(readers[kind], buf, &info, 1, 1) == 1 && info.valid_data) {
      const Header* r = (const Header*)reply;
      if (r->guid == guid && r->seq == h->seq) {
        const double trip = now() - t0;
        /* (a step call's round trip is its steps' time: not counted) */
        if (kind != STEP && timing_phase >= 0 && trip_count[timing_phase] < 512)
          trips[timing_phase][trip_count[timing_phase]++] = trip;
        return reply;
      }
      dds_sample_free(reply, kTypes[kind][1], DDS_FREE_CONTENTS);
      memset(reply, 0, kTypes[kind][1]->m_size);
    }
    dds_sleepfor(DDS_USECS(50));
  }
  free(reply);
  return NULL;
}

static void release(int kind, void* reply) {
  if (reply != NULL) dds_sample_free(reply, kTypes[kind][1], DDS_FREE_ALL);
}

static int resultOf(int kind, const void* reply) {
  if (reply == NULL) return -1;
  switch (kind) {
    case GET_STATE: return ((const simulation_interfaces_srv_dds__GetSimulationState_Response_*)reply)->result.result;
    case ENTITIES: return ((const simulation_interfaces_srv_dds__GetEntities_Response_*)reply)->result.result;
    case GET_ENTITY: return ((const simulation_interfaces_srv_dds__GetEntityState_Response_*)reply)->result.result;
    case SPAWN: return ((const simulation_interfaces_srv_dds__SpawnEntity_Response_*)reply)->result.result;
    default: /* the others' replies are the header and a Result */
      return ((const simulation_interfaces_srv_dds__SetSimulationState_Response_*)reply)->result.result;
  }
}

static int simple(int kind, void* request) {
  void* reply = call(kind, request);
  const int r = resultOf(kind, reply);
  release(kind, reply);
  return r;
}

static int setState(uint8_t state) {
  simulation_interfaces_srv_dds__SetSimulationState_Request_ q = {0};
  q.state.state = state;
  return simple(SET_STATE, &q);
}

static int simulationState(void) {
  simulation_interfaces_srv_dds__GetSimulationState_Request_ q = {0};
  simulation_interfaces_srv_dds__GetSimulationState_Response_* r = call(GET_STATE, &q);
  const int s = r != NULL && r->result.result == 1 ? r->state.state : -1;
  release(GET_STATE, r);
  return s;
}

static int step(uint64_t steps) {
  simulation_interfaces_srv_dds__StepSimulation_Request_ q = {0};
  q.steps = steps;
  return simple(STEP, &q);
}

/* the entity's state: stamp in ns, then x y z qx qy qz qw vx vy vz; the result code */
static int entityState(const char* name, double* out, long long* stamp) {
  simulation_interfaces_srv_dds__GetEntityState_Request_ q = {0};
  q.entity = (char*)name;
  simulation_interfaces_srv_dds__GetEntityState_Response_* r = call(GET_ENTITY, &q);
  const int code = resultOf(GET_ENTITY, r);
  if (code == 1) {
    const geometry_msgs_msg_dds__Pose_* p = &r->state.pose;
    const double v[10] = {p->position.x, p->position.y, p->position.z, p->orientation.x, p->orientation.y,
                          p->orientation.z, p->orientation.w, r->state.twist.linear.x, r->state.twist.linear.y,
                          r->state.twist.linear.z};
    memcpy(out, v, sizeof v);
    *stamp = (long long)r->state.header.stamp.sec * 1000000000LL + r->state.header.stamp.nanosec;
  }
  release(GET_ENTITY, r);
  return code;
}

/* the names GetEntities returns for `filter` and an optional category, joined by spaces */
static int entities(const char* filter, int category, int tags, char* out, size_t size) {
  simulation_interfaces_srv_dds__GetEntities_Request_ q = {0};
  q.filters.filter = (char*)filter;
  simulation_interfaces_msg_dds__EntityCategory_ c = {(uint8_t)category};
  if (category >= 0) q.filters.categories._buffer = &c, q.filters.categories._length = q.filters.categories._maximum = 1;
  char* tag = "red";
  if (tags) q.filters.tags.tags._buffer = &tag, q.filters.tags.tags._length = q.filters.tags.tags._maximum = 1;
  simulation_interfaces_srv_dds__GetEntities_Response_* r = call(ENTITIES, &q);
  const int code = resultOf(ENTITIES, r);
  out[0] = 0;
  if (code == 1)
    for (uint32_t k = 0; k < r->entities._length; ++k) {
      strncat(out, k ? " " : "", size - strlen(out) - 1);
      strncat(out, r->entities._buffer[k], size - strlen(out) - 1);
    }
  release(ENTITIES, r);
  return code;
}

static int cmp(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return x < y ? -1 : x > y;
}

static void printTrips(int phase, const char* what) {
  double* t = trips[phase];
  const int n = trip_count[phase];
  if (n == 0) return;
  qsort(t, (size_t)n, sizeof *t, cmp);
  printf("round trip %s: %d calls, median %.2f ms, p99 %.2f ms\n", what, n, 1e3 * t[n / 2], 1e3 * t[n * 99 / 100]);
}

static int contains(const dds_sequence_rmw_dds_common_msg_dds__Gid_* seq, const dds_guid_t* guid) {
  for (uint32_t k = 0; k < seq->_length; ++k)
    if (memcmp(seq->_buffer[k].data, guid->v, 16) == 0) return 1;
  return 0;
}

/* ROS 2's graph: ssx's participant announces the node /ssx on ros_discovery_info (kept for late
   readers), listing the reply writer and request reader this client matched */
static void checkGraph(dds_entity_t participant) {
  dds_instance_handle_t h;
  if (dds_get_matched_publications(readers[ENTITIES], &h, 1) != 1) return check(0, "the reply writer's identity");
  dds_builtintopic_endpoint_t* writer = dds_get_matched_publication_data(readers[ENTITIES], h);
  dds_instance_handle_t hr;
  if (dds_get_matched_subscriptions(writers[ENTITIES], &hr, 1) != 1) {
    dds_builtintopic_free_endpoint(writer);
    return check(0, "the request reader's identity");
  }
  dds_builtintopic_endpoint_t* reader = dds_get_matched_subscription_data(writers[ENTITIES], hr);
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t graph = dds_create_reader(
      participant, dds_create_topic(participant, &rmw_dds_common_msg_dds__ParticipantEntitiesInfo__desc, "ros_discovery_info", NULL, NULL),
      q, NULL);
  dds_delete_qos(q);
  int found = 0;
  const double t0 = now();
  while (!found && now() - t0 < 5.0) {
    void* samples[1] = {NULL};
    dds_sample_info_t info;
    if (dds_take(graph, samples, &info, 1, 1) == 1) {
      const rmw_dds_common_msg_dds__ParticipantEntitiesInfo_* m = samples[0];
      if (info.valid_data && memcmp(m->gid.data, writer->participant_key.v, 16) == 0 && m->node_entities_info_seq._length == 1) {
        const rmw_dds_common_msg_dds__NodeEntitiesInfo_* n = &m->node_entities_info_seq._buffer[0];
        found = 1;
        printf("  ros_discovery_info: node %s%s with %u readers and %u writers\n", n->node_namespace, n->node_name,
               n->reader_gid_seq._length, n->writer_gid_seq._length);
        check(strcmp(n->node_namespace, "/") == 0 && strcmp(n->node_name, "ssx") == 0, "the node is /ssx");
        check(contains(&n->writer_gid_seq, &writer->key) && contains(&n->reader_gid_seq, &reader->key),
              "its endpoints include the services' reply writer and request reader");
      }
      dds_return_loan(graph, samples, 1);
    } else {
      dds_sleepfor(DDS_MSECS(5));
    }
  }
  check(found, "ssx's participant is on ros_discovery_info");
  dds_builtintopic_free_endpoint(writer);
  dds_builtintopic_free_endpoint(reader);
}

int main(int argc, char** argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: services_client TIMEOUT_S\n");
    return 2;
  }
  timeout = atof(argv[1]);
  const char* domain_env = getenv("ROS_DOMAIN_ID");
  const dds_entity_t participant = dds_create_participant(domain_env ? (dds_domainid_t)atoi(domain_env) : 0, NULL, NULL);
  if (participant < 0) return fprintf(stderr, "services_client: no DDS participant\n"), 1;
  srand((unsigned)time(NULL));
  guid = ((uint64_t)rand() << 32) ^ (uint64_t)rand() ^ 0x5555u;
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  const dds_data_representation_id_t xcdr1[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, xcdr1);
  char name[128];
  for (int k = 0; k < KINDS; ++k) {
    snprintf(name, sizeof name, "rq/%sRequest", kNames[k]);
    writers[k] = dds_create_writer(participant, dds_create_topic(participant, kTypes[k][0], name, NULL, NULL), q, NULL);
    snprintf(name, sizeof name, "rr/%sReply", kNames[k]);
    readers[k] = dds_create_reader(participant, dds_create_topic(participant, kTypes[k][1], name, NULL, NULL), q, NULL);
  }
  dds_delete_qos(q);
  /* the service is up when every request writer and reply reader matched ssx's */
  const double t0 = now();
  int matched = 0;
  while (!matched && now() - t0 < timeout) {
    matched = 1;
    for (int k = 0; k < KINDS; ++k) {
      dds_publication_matched_status_t w;
      dds_subscription_matched_status_t r;
      if (dds_get_publication_matched_status(writers[k], &w) < 0 || w.current_count == 0) matched = 0;
      if (dds_get_subscription_matched_status(readers[k], &r) < 0 || r.current_count == 0) matched = 0;
    }
    if (!matched) dds_sleepfor(DDS_MSECS(20));
  }
  check(matched, "every service's request and reply topics matched ssx's");
  if (!matched) return 1;
  checkGraph(participant);
  dds_sleepfor(DDS_MSECS(200)); /* (the run has started) */

  /* what the simulator offers */
  simulation_interfaces_srv_dds__GetSimulatorFeatures_Request_ fq = {0};
  simulation_interfaces_srv_dds__GetSimulatorFeatures_Response_* f = call(FEATURES, &fq);
  int stepping = 0, spawning = 0;
  for (uint32_t k = 0; f != NULL && k < f->features.features._length; ++k) {
    stepping |= f->features.features._buffer[k] == 31;
    spawning |= f->features.features._buffer[k] == 0;
  }
  check(f != NULL && stepping && !spawning, "features: single stepping offered (31), spawning not (0)");
  release(FEATURES, f);

  /* while it plays */
  timing_phase = 0;
  char names[256];
  check(simulationState() == 1, "the run plays (STATE_PLAYING)");
  check(entities("^q", -1, 0, names, sizeof names) == 1 && strcmp(names, "q0 q1") == 0, "entities matching ^q: q0 q1");
  check(entities("", 5, 0, names, sizeof names) == 1 && strcmp(names, "ground") == 0, "static objects: ground");
  check(entities("", 1, 0, names, sizeof names) == 1 && strcmp(names, "q0 q1") == 0, "robots: q0 q1");
  check(entities("(", -1, 0, names, sizeof names) == 4, "a filter that is no regular expression: OPERATION_FAILED");
  check(entities("", -1, 1, names, sizeof names) == 0, "a tags filter: FEATURE_UNSUPPORTED");
  check(step(5) == 4, "step_simulation while playing: OPERATION_FAILED");
  double s0[10], s1[10], s2[10];
  long long t_a = 0, t_b = 0;
  check(entityState("nope", s0, &t_a) == 2, "an unknown entity: NOT_FOUND");
  for (int k = 0; k < 20; ++k) entityState("q0", s0, &t_a);

  /* paused: time holds, steps are exactly those asked */
  check(setState(2) == 1, "pause (STATE_PAUSED)");
  timing_phase = 1;
  check(setState(2) == 101, "pause again: ALREADY_IN_TARGET_STATE");
  check(simulationState() == 2, "the run is paused");
  entityState("q0", s0, &t_a);
  dds_sleepfor(DDS_MSECS(300));
  entityState("q0", s1, &t_b);
  check(t_a == t_b && memcmp(s0, s1, sizeof s0) == 0, "paused for 0.3 s: the same time and state");
  check(step(10) == 1, "step_simulation 10");
  entityState("q0", s1, &t_b);
  printf("  time %lld ns -> %lld ns\n", t_a, t_b);
  check(t_b - t_a == 10 * 2000000LL, "10 steps of 2 ms taken, no more");
  for (int k = 0; k < 20; ++k) entityState("q0", s1, &t_b);

  /* an entity set while paused reads back as set */
  simulation_interfaces_srv_dds__SetEntityState_Request_ sq = {0};
  sq.entity = "q1";
  sq.state.header.frame_id = "world";
  sq.state.pose.position = (geometry_msgs_msg_dds__Point_){2.0, -1.0, 1.5};
  sq.state.pose.orientation = (geometry_msgs_msg_dds__Quaternion_){0, 0, sin(0.25), cos(0.25)};
  sq.set_pose = 1;
  sq.set_twist = 1;
  check(simple(SET_ENTITY, &sq) == 1, "set_entity_state q1");
  entityState("q1", s2, &t_b);
  check(fabs(s2[0] - 2.0) < 1e-9 && fabs(s2[1] + 1.0) < 1e-9 && fabs(s2[2] - 1.5) < 1e-9 && fabs(s2[5] - sin(0.25)) < 1e-9 &&
            fabs(s2[6] - cos(0.25)) < 1e-9 && fabs(s2[7]) < 1e-9,
        "q1 reads back where it was put (1e-9), at rest");
  sq.state.pose.orientation = (geometry_msgs_msg_dds__Quaternion_){0, 0, 0, 0};
  check(simple(SET_ENTITY, &sq) == 101, "a zero quaternion: INVALID_POSE");
  sq.entity = "ground";
  sq.state.pose.orientation = (geometry_msgs_msg_dds__Quaternion_){0, 0, 0, 1};
  check(simple(SET_ENTITY, &sq) == 4, "moving the ground: OPERATION_FAILED");
  simulation_interfaces_srv_dds__SpawnEntity_Request_ spq = {0};
  spq.name = "q2";
  spq.entity_resource.uri = "file:///robot.urdf";
  spq.entity_resource.resource_string = "";
  spq.entity_namespace = "";
  spq.initial_pose.header.frame_id = "world";
  check(simple(SPAWN, &spq) == 0, "spawn_entity: FEATURE_UNSUPPORTED");
  simulation_interfaces_srv_dds__DeleteEntity_Request_ dq = {0};
  dq.entity = "q1";
  check(simple(DELETE, &dq) == 0, "delete_entity: FEATURE_UNSUPPORTED");

  /* a reset goes back to time 0; the same steps after it give the same bits */
  simulation_interfaces_srv_dds__ResetSimulation_Request_ rq = {0};
  rq.scope = 1;
  check(simple(RESET, &rq) == 0, "reset of time alone: FEATURE_UNSUPPORTED");
  rq.scope = 0;
  check(simple(RESET, &rq) == 1, "reset_simulation");
  entityState("q0", s0, &t_a);
  check(t_a == 0, "after the reset: time 0");
  const double stepped_at = now();
  check(step(250) == 1, "step_simulation 250 after the reset");
  const double took = now() - stepped_at;
  printf("  250 steps asked while paused took %.1f ms (0.5 s of simulated time)\n", 1e3 * took);
  check(took < 0.4, "steps asked while paused are taken at once, not paced in real time");
  entityState("q0", s1, &t_a);
  check(simple(RESET, &rq) == 1 && step(250) == 1, "reset and 250 steps again");
  entityState("q0", s2, &t_b);
  printf("  q0 after 250 steps: z %.9f, then %.9f (t %lld, %lld ns)\n", s1[2], s2[2], t_a, t_b);
  check(t_a == 500000000LL && t_b == t_a && memcmp(s1, s2, sizeof s1) == 0,
        "the same 250 steps after each reset: the same time and state, bit for bit");
  check(setState(0) == 1 && simulationState() == 0, "stop (STATE_STOPPED): paused at the start");
  entityState("q0", s0, &t_a);
  check(t_a == 0, "stopped: time 0");

  /* playing again */
  timing_phase = -1;
  check(setState(1) == 1, "play (STATE_PLAYING)");
  dds_sleepfor(DDS_MSECS(500));
  timing_phase = 0;
  entityState("q0", s0, &t_a);
  check(simulationState() == 1 && t_a > 100000000LL, "playing again: time goes on");
  printTrips(0, "while playing (real time, 500 Hz steps)");
  printTrips(1, "while paused");
  timing_phase = -1;
  check(setState(3) == 1, "quit (STATE_QUITTING)");
  dds_delete(participant);
  printf("%d check(s) failed\n", failures);
  return failures == 0 ? 0 : 1;
}
