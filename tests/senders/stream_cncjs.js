// Streams a G-code file to a grbl controller with cncjs (npm) run
// headless: starts the cncjs server on a free loopback port with a private
// configuration, connects to it as its web client does (socket.io, a JWT
// signed with the configuration's secret), opens PORT with controller type
// Grbl, loads the file (`gcode:load`) and starts it (`gcode:start`):
// cncjs's own sender streams it, character counting, and polls `?` itself.
// The driver adds `?` (`statusreport`) every 0.2 s (each once the one
// before was answered), optionally holds the feed (`feedhold`: `!`)
// HOLD_AT s after the start and resumes (`cyclestart`: `~`) HOLD_FOR s
// later, and waits for the workflow to come back to idle with the whole
// job sent and acknowledged. Prints a JSON summary. Usage: stream_cncjs.js PORT FILE [HOLD_AT HOLD_FOR]
// (NODE_PATH: the node_modules cncjs is installed in).
'use strict';
const { spawn } = require('child_process');
const fs = require('fs');
const net = require('net');
const os = require('os');
const path = require('path');
const jwt = require('jsonwebtoken');
const io = require('socket.io-client');

const [port, file, holdAt, holdFor] = process.argv.slice(2);
const summary = { sender: 'cncjs', errors: [], alarms: [], statuses: 0, polls: 0 };
const gcode = fs.readFileSync(file, 'utf8');

function freePort() {
  return new Promise((resolve, reject) => {
    const server = net.createServer();
    server.listen(0, '127.0.0.1', () => {
      const { port: p } = server.address();
      server.close(() => resolve(p));
    });
    server.on('error', reject);
  });
}

function fail(why) {
  console.log(JSON.stringify({ ...summary, completed: false, why }));
  process.exit(1);
}

async function connect(httpPort, secret) {
  const token = jwt.sign({ id: '', name: 'senders-test' }, secret, { expiresIn: '1h' });
  for (let tries = 0; tries < 100; tries += 1) {
    const socket = io.connect(`ws://127.0.0.1:${httpPort}`, {
      query: `token=${token}`,
      reconnection: false,
      transports: ['websocket'],
    });
    const ok = await new Promise((resolve) => {
      socket.on('connect', () => resolve(true));
      socket.on('connect_error', () => resolve(false));
      socket.on('error', () => resolve(false));
    });
    if (ok) {
      return socket;
    }
    socket.close();
    await new Promise((r) => setTimeout(r, 200));
  }
  return fail('cannot reach the cncjs server');
}

function emit(socket, ...args) {
  return new Promise((resolve, reject) => {
    socket.emit(...args, (err, data) => (err ? reject(err) : resolve(data)));
  });
}

async function main() {
  const home = fs.mkdtempSync(path.join(os.tmpdir(), 'cncjs-'));
  const config = path.join(home, 'cncrc.json');
  const secret = 'senders-test-secret';
  fs.writeFileSync(config, JSON.stringify({ secret, state: {}, macros: [], users: [] }));
  const httpPort = await freePort();
  const main = require.resolve('cncjs/bin/cncjs');
  const server = spawn(process.execPath, [main, '-H', '127.0.0.1', '-p', String(httpPort), '-c', config], {
    env: { ...process.env, HOME: home },
    stdio: ['ignore', 'ignore', 'inherit'],
  });
  const stopServer = () => {
    server.kill('SIGTERM');
    fs.rmSync(home, { recursive: true, force: true });
  };
  process.on('exit', stopServer);
  const socket = await connect(httpPort, secret);
  let workflow = 'idle';
  let ran = false;
  // The most lines sent and acknowledged (`gcode:stop` at the end
  // rewinds the sender to 0).
  const progress = { sent: 0, received: 0, total: 0 };
  socket.on('workflow:state', (state) => {
    workflow = state;
    ran = ran || state === 'running';
  });
  socket.on('sender:status', (status) => {
    progress.sent = Math.max(progress.sent, status.sent);
    progress.received = Math.max(progress.received, status.received);
    progress.total = status.total;
  });
  let booted = false;
  let polled = false;
  socket.on('serialport:read', (line) => {
    if (line.startsWith('<')) {
      summary.statuses += 1;
      polled = false;
    } else if (line.startsWith('error')) {
      summary.errors.push(line);
    } else if (line.startsWith('ALARM')) {
      summary.alarms.push(line);
    } else if (line.startsWith('Grbl ')) {
      booted = true;
    }
  });
  await emit(socket, 'open', port, { controllerType: 'Grbl', baudrate: 115200, rtscts: false });
  const deadline = (s) => Date.now() + s * 1000;
  const until = async (cond, s, why) => {
    const end = deadline(s);
    while (!cond()) {
      if (Date.now() > end) {
        fail(why);
      }
      await new Promise((r) => setTimeout(r, 20));
    }
  };
  await until(() => booted, 10, 'no banner');
  // cncjs reads the settings ($$) on connect; let it settle.
  await new Promise((r) => setTimeout(r, 1000));
  const job = path.basename(file);
  await emit(socket, 'command', port, 'gcode:load', job, gcode);
  summary.statuses = 0;
  const start = Date.now();
  // One `?` every 0.2 s, the next once the last was answered: cncjs
  // echoes the status report that follows a client's `?` (one flag, not a
  // count), so two `?` written together (timers bunched after a stall of
  // the event loop) would show one answer.
  summary.deferred = 0;
  const poller = setInterval(() => {
    if (polled) {
      summary.deferred += 1;
      return;
    }
    polled = true;
    summary.polls += 1;
    socket.emit('command', port, 'statusreport');
  }, 200);
  socket.emit('command', port, 'gcode:start');
  if (holdAt !== undefined) {
    setTimeout(() => {
      socket.emit('command', port, 'feedhold');
      summary.held_in = workflow;
      setTimeout(() => socket.emit('command', port, 'cyclestart'), Number(holdFor) * 1000);
    }, Number(holdAt) * 1000);
  }
  // The sender stops the workflow once the machine is idle after the
  // last line (its `%wait` dwell) was acknowledged.
  await until(() => ran && workflow === 'idle', 400, 'the job did not finish');
  summary.seconds = (Date.now() - start) / 1000;
  clearInterval(poller);
  await new Promise((r) => setTimeout(r, 500)); // the last poll's report
  Object.assign(summary, progress);
  summary.completed = progress.total > 0 && progress.received === progress.total;
  await emit(socket, 'close', port).catch(() => {});
  socket.close();
  console.log(JSON.stringify(summary));
  stopServer();
  process.exit(0);
}

main().catch((err) => fail(String(err)));
