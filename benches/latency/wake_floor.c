// The floor of a cold wake-up by mechanism (BENCHMARKS.md section 1, "The cold wake-up is the
// VM's"): one process sends to another, pinned to the other CPU, one frame every PACE_US (1 ms:
// each a cold wake-up), and the receiver records CLOCK_MONOTONIC at receipt minus the sender's
// stamp. MODE: uds (blocking recv on a Unix datagram socket), uds-epoll (the same after
// epoll_wait), futex (FUTEX_WAIT/FUTEX_WAKE on a word in shared memory), eventfd (blocking
// read), eventfd-epoll, pipe-epoll. Not part of `cargo bench`; build and run by hand:
//
//   cc -O2 -o /tmp/wake-floor benches/latency/wake_floor.c
//   for m in uds uds-epoll futex eventfd-epoll; do /tmp/wake-floor $m 3000; done
//
// Prints p50, p99, p99.9 and max of the frames after the first 300.
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sched.h>
#include <time.h>
#include <stdint.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <linux/futex.h>
#include <sys/syscall.h>
#include <stdatomic.h>

static uint64_t now(void){struct timespec t;clock_gettime(CLOCK_MONOTONIC,&t);return t.tv_sec*1000000000ull+t.tv_nsec;}
static void pin(int c){cpu_set_t s;CPU_ZERO(&s);CPU_SET(c,&s);sched_setaffinity(0,sizeof s,&s);}
static int cmp(const void*a,const void*b){uint64_t x=*(uint64_t*)a,y=*(uint64_t*)b;return x<y?-1:x>y;}
struct shm { _Atomic uint64_t stamp; _Atomic uint32_t fut; _Atomic uint32_t back; uint64_t lat[20000]; };
static long futex(_Atomic uint32_t*u,int op,uint32_t v){return syscall(SYS_futex,u,op,v,NULL,NULL,0);}
int main(int argc,char**argv){
  if(argc<2){fprintf(stderr,"usage: %s MODE [FRAMES [PACE_US]]\n",argv[0]);return 2;}
  const char*mode=argv[1]; int n=argc>2?atoi(argv[2]):3000; int pace_us=argc>3?atoi(argv[3]):1000;
  if(n<=300||n>20000){fprintf(stderr,"FRAMES: 301 to 20000\n");return 2;}
  struct shm*s=mmap(0,sizeof *s,PROT_READ|PROT_WRITE,MAP_SHARED|MAP_ANONYMOUS,-1,0);
  int sv[2]; socketpair(AF_UNIX,SOCK_DGRAM,0,sv);
  int rv[2]; socketpair(AF_UNIX,SOCK_DGRAM,0,rv); // reply path
  int efd=eventfd(0,0); int pfd[2]; pipe(pfd);
  pid_t p=fork();
  if(p==0){ pin(1);
    int ep=epoll_create1(0); struct epoll_event ev={.events=EPOLLIN};
    int wfd = !strcmp(mode,"uds-epoll")? sv[1] : !strcmp(mode,"eventfd-epoll")? efd : !strcmp(mode,"pipe-epoll")? pfd[0] : -1;
    if(wfd>=0){ev.data.fd=wfd;epoll_ctl(ep,EPOLL_CTL_ADD,wfd,&ev);}
    char buf[600];
    for(int i=0;i<n;i++){
      uint64_t t;
      if(!strcmp(mode,"uds")){ recv(sv[1],buf,sizeof buf,0); t=now(); }
      else if(!strcmp(mode,"futex")){ while(atomic_exchange(&s->fut,0)==0) futex(&s->fut,FUTEX_WAIT,0); t=now(); }
      else if(!strcmp(mode,"eventfd")){ uint64_t v; read(efd,&v,8); t=now(); }
      else { struct epoll_event e; epoll_wait(ep,&e,1,-1);
        if(wfd==sv[1]) recv(sv[1],buf,sizeof buf,0); else if(wfd==efd){uint64_t v;read(efd,&v,8);} else read(pfd[0],buf,1);
        t=now(); }
      s->lat[i]=t-atomic_load(&s->stamp);
      atomic_store(&s->back,1); futex(&s->back,FUTEX_WAKE,1);
    }
    _exit(0);
  }
  pin(0); char frame[548]={0};
  for(int i=0;i<n;i++){
    uint64_t until=now()+pace_us*1000ull; while(now()<until) usleep(pace_us>50?pace_us/2:0);
    atomic_store(&s->stamp,now());
    if(!strcmp(mode,"uds")||!strcmp(mode,"uds-epoll")) send(sv[0],frame,sizeof frame,0);
    else if(!strcmp(mode,"futex")){ atomic_store(&s->fut,1); futex(&s->fut,FUTEX_WAKE,1);}
    else if(!strncmp(mode,"eventfd",7)){ uint64_t v=1; write(efd,&v,8);}
    else write(pfd[1],"x",1);
    while(atomic_exchange(&s->back,0)==0) futex(&s->back,FUTEX_WAIT,0);
  }
  waitpid(p,0,0);
  uint64_t*l=s->lat+300; int m=n-300; qsort(l,m,8,cmp);
  printf("%-14s p50 %6.2f p99 %7.2f p99.9 %7.2f max %7.2f us\n",mode,l[m/2]/1e3,l[m*99/100]/1e3,l[m*999/1000]/1e3,l[m-1]/1e3);
}
