/* sha256.h: private to import/: SHA-256 (FIPS 180-4) for the level-set
 * cache, which names a grid by the hash of everything it was made from. */
#ifndef CS_SHA256_H
#define CS_SHA256_H

#include <stddef.h>
#include <stdint.h>

typedef struct cs_sha256 {
    uint32_t h[8];
    uint64_t length;       /* bytes hashed so far */
    unsigned char block[64];
    size_t used;           /* bytes waiting in block */
} cs_sha256;

void cs_sha256_init(cs_sha256 *s);
void cs_sha256_update(cs_sha256 *s, const void *data, size_t len);
/* Writes 64 lowercase hex digits and a NUL. */
void cs_sha256_hex(cs_sha256 *s, char hex[65]);

#endif
