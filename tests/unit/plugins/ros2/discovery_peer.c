/* A ROS 2 Humble tool's view of the graph, without ROS 2: reads ros_discovery_info with Humble's
 * types (rmw_dds_common's Gid of 24 bytes) until a participant announces the node /NODE, then checks
 * that its ids are DDS GUIDs as Humble's rmw_cyclonedds writes them (16 bytes, then 8 zeros), that
 * the participant's id is the one DDS discovered for the writer, and that the writer itself is among
 * the node's writers.
 *   discovery_peer TIMEOUT_S NODE     exit 0 when all held */
#include "humble_discovery.h"

#include <dds/dds.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;
static void check(int ok, const char* what) {
  printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++failures;
}

typedef ssx_humble_rmw_dds_common_msg_dds__Gid_ Gid;

static int tailZero(const Gid* g) {
  for (int k = 16; k < 24; ++k)
    if (g->data[k] != 0) return 0;
  return 1;
}

int main(int argc, char** argv) {
  setvbuf(stdout, NULL, _IONBF, 0);
  if (argc < 3) return fprintf(stderr, "usage: discovery_peer TIMEOUT_S NODE\n"), 2;
  const double timeout = atof(argv[1]);
  const char* node = argv[2];
  const char* domain_env = getenv("ROS_DOMAIN_ID");
  const dds_entity_t p = dds_create_participant(domain_env ? (dds_domainid_t)atoi(domain_env) : 0, NULL, NULL);
  if (p < 0) return fprintf(stderr, "discovery_peer: no DDS participant\n"), 1;
  const dds_topic_descriptor_t type = ssx_humble_discovery_type();
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t reader = dds_create_reader(p, dds_create_topic(p, &type, "ros_discovery_info", NULL, NULL), q, NULL);
  dds_delete_qos(q);
  int found = 0;
  for (double waited = 0; !found && waited < timeout; waited += 0.005) {
    void* samples[1] = {NULL};
    dds_sample_info_t info;
    if (dds_take(reader, samples, &info, 1, 1) != 1) {
      dds_sleepfor(DDS_MSECS(5));
      continue;
    }
    const ssx_humble_rmw_dds_common_msg_dds__ParticipantEntitiesInfo_* m = samples[0];
    if (info.valid_data && m->node_entities_info_seq._length == 1 &&
        strcmp(m->node_entities_info_seq._buffer[0].node_name, node) == 0) {
      const ssx_humble_rmw_dds_common_msg_dds__NodeEntitiesInfo_* n = &m->node_entities_info_seq._buffer[0];
      found = 1;
      printf("  ros_discovery_info (Humble's layout): node %s%s with %u readers and %u writers\n", n->node_namespace,
             n->node_name, n->reader_gid_seq._length, n->writer_gid_seq._length);
      check(strcmp(n->node_namespace, "/") == 0, "in the namespace /");
      dds_builtintopic_endpoint_t* writer = dds_get_matched_publication_data(reader, info.publication_handle);
      if (writer == NULL) {
        check(0, "the writer's identity");
      } else {
        check(memcmp(m->gid.data, writer->participant_key.v, 16) == 0 && tailZero(&m->gid),
              "the participant's id: its GUID's 16 bytes, then 8 zeros");
        int self = 0, zeros = 1;
        for (uint32_t k = 0; k < n->writer_gid_seq._length; ++k) {
          self |= memcmp(n->writer_gid_seq._buffer[k].data, writer->key.v, 16) == 0;
          zeros &= tailZero(&n->writer_gid_seq._buffer[k]);
        }
        for (uint32_t k = 0; k < n->reader_gid_seq._length; ++k) zeros &= tailZero(&n->reader_gid_seq._buffer[k]);
        check(self, "the node's writers include this ros_discovery_info writer");
        check(zeros && n->reader_gid_seq._length > 0 && n->writer_gid_seq._length > 1,
              "every reader's and writer's id: 16 bytes, then 8 zeros");
        dds_builtintopic_free_endpoint(writer);
      }
    }
    dds_return_loan(reader, samples, 1);
  }
  check(found, "the node is on ros_discovery_info");
  dds_delete(p);
  printf("%d check(s) failed\n", failures);
  return failures == 0 ? 0 : 1;
}
